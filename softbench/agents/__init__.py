"""The agent registry: ``make(name, robot, seed, profile)`` and ``AGENTS``.

Adding an agent is one small file with a ``build(robot, seed, profile, show_progress) -> Agent``
function and one line in ``_AGENTS`` below; tests then cover it with no new test code.
"""

import collections
import importlib
from typing import Callable

from softbench import profiles
from softbench import robots
from softbench.data import seeding
from softbench.agents.base import Agent
from softbench.agents.base import EpisodeInfo

AgentEntry = collections.namedtuple("AgentEntry", ["module", "learned", "description"])

_AGENTS = {
    "smpl": AgentEntry("softbench.agents.smpl_agent", True,
                       "SMPL: progressive LSTM columns, one per module"),
    "mlp": AgentEntry("softbench.agents.mlp", True, "MLP baseline (3 layers)"),
    "lstm": AgentEntry("softbench.agents.lstm", True, "LSTM baseline"),
    "vae-lstm": AgentEntry("softbench.agents.vae_lstm", True, "variational LSTM baseline"),
    "bilstm": AgentEntry("softbench.agents.bilstm", True, "bidirectional LSTM baseline"),
    "sac": AgentEntry("softbench.agents.sac", True,
                      "SAC (Stable-Baselines3): model-free RL, learns by acting on the arm"),
    "zero": AgentEntry("softbench.agents.zero", False, "always the zero action (sanity check)"),
    "random": AgentEntry("softbench.agents.random_actions", False,
                         "uniform random actions (sanity check)"),
    "reference": AgentEntry("softbench.agents.reference", False,
                            "model-based: uses the simulator itself (what the physics allows)"),
}
AGENTS = tuple(_AGENTS)


def describe(name: str) -> AgentEntry:
  if name not in _AGENTS:
    raise ValueError(f"unknown agent {name!r}; choose one of {', '.join(AGENTS)}")
  return _AGENTS[name]


def make(name: str, robot: str | robots.SoftArm, seed: int = 0,
         profile: str | profiles.Profile = profiles.DEFAULT_PROFILE,
         show_progress: bool = False) -> Agent:
  """Agent ``name`` for ``robot``, built (and trained, if it learns) with ``seed`` and
  ``profile``; ``show_progress`` shows training progress bars.

  Raises:
    ValueError: unknown agent, robot or profile, or a negative seed (one line).
  """
  entry = describe(name)
  arm = robots.make(robot) if isinstance(robot, str) else robot
  profile = profiles.get(profile) if isinstance(profile, str) else profile
  seeding.check_seed(seed)
  build: Callable[..., Agent] = importlib.import_module(entry.module).build
  return build(arm, seed, profile, show_progress)


def learner(name: str):
  """The ``softbench.agents.learned.Learner`` of an agent trained on babbling (an inverse model
  in closed loop, ``smpl.training``), None for the others (sac learns by interaction)."""
  entry = describe(name)
  return importlib.import_module(entry.module).LEARNER if entry.learned else None


def training_summary(name: str, robot: robots.SoftArm, seed: int,
                     profile: profiles.Profile) -> dict | None:
  """What an agent that learns by acting spent on ``seed``'s training (environment steps,
  episodes, wall time), read from its cache; None for the other agents."""
  summary = getattr(importlib.import_module(describe(name).module), "training_summary", None)
  return None if summary is None else summary(robot, seed, profile)


def babbling_learners() -> tuple[str, ...]:
  """The agents with a ``learner``: those that tuning, retraining and adaptive activation
  take."""
  return tuple(name for name in AGENTS if learner(name) is not None)


__all__ = ["AGENTS", "Agent", "EpisodeInfo", "babbling_learners", "describe", "learner", "make",
           "training_summary"]
