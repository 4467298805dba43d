"""The agent registry: ``make(name, robot, seed, profile)`` and ``AGENTS``.

An agent trained on babbling in closed loop is a ``Learner`` (its inverse model and search space)
in one line of ``_AGENTS``: SMPL's columns, or a centralised model such as ``smpl.baselines``'s.
Any other agent is one small file with a ``build(robot, seed, profile, show_progress) -> Agent``
function and one line here. ``register`` adds an agent from outside the package for one
process; an installed package declares its agents for every process (the command line's, its
seed and sweep workers) as entry points of the group ``ENTRY_POINT_GROUP``, each named after its
agent and pointing at an ``AgentEntry``::

  [project.entry-points."softbench.agents"]
  hold-still = "my_package.agents:HOLD_STILL"

Tests cover every entry with no new test code.
"""

import collections
import importlib
from importlib import metadata
from typing import Callable

from softbench import profiles
from softbench import registries
from softbench import robots
from softbench import storage
from softbench.agents.base import Agent
from softbench.agents.base import EpisodeInfo
from softbench.agents.learners import OPTIMISATION
from softbench.agents.learners import RECURRENT
from softbench.agents.learners import Choice
from softbench.agents.learners import Learner
from softbench.agents.learners import LogUniform
from softbench.data import seeding

AgentEntry = collections.namedtuple(
  "AgentEntry", ["module", "learned", "description", "learner", "oracle"], defaults=[None, False]
)
"""An agent: the module whose ``build`` makes it (None for a babbling learner, which
``agents.learned`` trains), whether it learns, a one-line description, its ``Learner`` (None:
not trained on babbling), and whether it is an oracle: one that uses the simulator itself, which
the leaderboard shows as a bound, apart from the ranking."""


def _babbling_learner(description: str, learner: Learner) -> AgentEntry:
  return AgentEntry(None, True, description, learner)


_AGENTS = {
  # SMPL's width and depth stay at the paper's 2 LSTM layers of 32 units per column (SPEC 5):
  # only its optimisation is tuned.
  "smpl": _babbling_learner(
    "SMPL: progressive LSTM columns, one per module",
    Learner(per_module=True, search_space=OPTIMISATION),
  ),
  "mlp": _babbling_learner(
    "MLP baseline (3 layers)",
    Learner(
      False,
      "smpl.baselines:MLPInverse",
      {**OPTIMISATION, "hidden_size": Choice((32, 64, 128, 256))},
    ),
  ),
  "lstm": _babbling_learner(
    "LSTM baseline", Learner(False, "smpl.baselines:LSTMInverse", {**OPTIMISATION, **RECURRENT})
  ),
  "vae-lstm": _babbling_learner(
    "variational LSTM baseline",
    Learner(
      False,
      "smpl.baselines:VAELSTMInverse",
      {
        **OPTIMISATION,
        **RECURRENT,
        "latent_size": Choice((2, 4, 8, 16)),
        "kl_weight": LogUniform(1e-5, 1e-1),
      },
    ),
  ),
  "bilstm": _babbling_learner(
    "bidirectional LSTM baseline",
    Learner(False, "smpl.baselines:BiLSTMInverse", {**OPTIMISATION, **RECURRENT}),
  ),
  "sac": AgentEntry(
    "softbench.agents.sac",
    True,
    "SAC (Stable-Baselines3): model-free RL, learns by acting on the arm",
  ),
  "zero": AgentEntry("softbench.agents.zero", False, "always the zero action (sanity check)"),
  "random": AgentEntry(
    "softbench.agents.random_actions", False, "uniform random actions (sanity check)"
  ),
  "reference": AgentEntry(
    "softbench.agents.reference",
    False,
    "model-based: uses the simulator itself (what the physics allows)",
    oracle=True,
  ),
}
AGENTS = tuple(_AGENTS)


def register(name: str, entry: AgentEntry) -> None:
  """Adds agent ``name`` to the registry (``AGENTS`` is rebound to include it).

  Raises:
    ValueError: the name is taken or malformed, or the entry is inconsistent (one line).
  """
  global AGENTS
  registries.check_new_name("agent", name, _AGENTS)
  if (entry.module is None) == (entry.learner is None):
    raise ValueError(f"agent {name!r}: give either the module that builds it or its learner")
  _AGENTS[name] = entry
  AGENTS = tuple(_AGENTS)


ENTRY_POINT_GROUP = "softbench.agents"


def register_installed() -> list[str]:
  """Registers the agents that installed packages declare (``ENTRY_POINT_GROUP``) and returns
  their names; one that cannot be loaded or registered is left out, with why, in ``LEFT_OUT``
  (which the command line prints as one-line warnings, and ``describe`` names)."""
  added = []
  for point in metadata.entry_points(group=ENTRY_POINT_GROUP):
    if point.name in _INSTALLED:
      continue  # Registered by an earlier call.
    try:
      entry = point.load()
      if not isinstance(entry, AgentEntry):
        raise TypeError(f"it names a {type(entry).__name__}, not a softbench.agents.AgentEntry")
      register(point.name, entry)
    except Exception as error:  # A broken package must not break softbench: it is named.
      LEFT_OUT[point.name] = (
        f"agent {point.name!r} of entry point {point.value!r} left out: {storage.first_line(error)}"
      )
      continue
    _INSTALLED[point.name] = entry
    added.append(point.name)
  return added


_INSTALLED: dict[str, AgentEntry] = {}  # The agents register_installed added, by name.
LEFT_OUT: dict[str, str] = {}  # Installed agents that could not be registered: name -> why.


def describe(name: str) -> AgentEntry:
  if name in LEFT_OUT and name not in _AGENTS:
    raise ValueError(LEFT_OUT[name])
  if name not in _AGENTS:
    raise ValueError(f"unknown agent {name!r}; choose one of {', '.join(AGENTS)}")
  return _AGENTS[name]


def make(
  name: str,
  robot: "str | robots.SoftArm",
  seed: int = 0,
  profile: str | profiles.Profile = profiles.DEFAULT_PROFILE,
  show_progress: bool = False,
  acting=None,
) -> Agent:
  """Agent ``name`` for ``robot``, built (and trained, if it learns) with ``seed`` and
  ``profile``; ``show_progress`` shows training progress bars. ``acting`` (``learned.Acting``;
  None: its defaults) says how an agent trained on babbling acts; the other agents take none.

  Raises:
    ValueError: unknown agent, robot or profile, or a negative seed (one line).
  """
  entry = describe(name)
  arm = robots.make(robot) if isinstance(robot, str) else robot
  profile = profiles.get(profile) if isinstance(profile, str) else profile
  seeding.check_seed(seed)
  if entry.learner is not None:
    learned = importlib.import_module("softbench.agents.learned")
    return learned.build_agent(
      name,
      arm,
      seed,
      profile,
      entry.learner.per_module,
      entry.learner.make_model,
      show_progress,
      learned.Acting() if acting is None else acting,
    )
  build: Callable[..., Agent] = importlib.import_module(entry.module).build
  return build(arm, seed, profile, show_progress)


def is_oracle(name: str) -> bool:
  """Whether agent ``name`` is a registered oracle (``AgentEntry.oracle``); an agent this
  installation does not know (a record of another package's) is not."""
  return name in _AGENTS and _AGENTS[name].oracle


def is_learned(name: str) -> bool:
  """Whether agent ``name`` learns; an agent this installation does not know is taken to."""
  return name not in _AGENTS or _AGENTS[name].learned


def learner(name: str) -> Learner | None:
  """The ``Learner`` of an agent trained on babbling (an inverse model in closed loop,
  ``smpl.training``), None for the others (sac learns by interaction)."""
  return describe(name).learner


def training_summary(
  name: str, robot: "robots.SoftArm", seed: int, profile: profiles.Profile
) -> dict | None:
  """What an agent that learns by acting spent on ``seed``'s training (environment steps,
  episodes, wall time), read from its cache; None for the other agents."""
  module = describe(name).module
  summary = (
    None if module is None else getattr(importlib.import_module(module), "training_summary", None)
  )
  return None if summary is None else summary(robot, seed, profile)


def babbling_learners() -> tuple[str, ...]:
  """The agents with a ``learner``: those that tuning, retraining and adaptive activation
  take."""
  return tuple(name for name in AGENTS if learner(name) is not None)


register_installed()

__all__ = [
  "AGENTS",
  "Agent",
  "AgentEntry",
  "EpisodeInfo",
  "Learner",
  "babbling_learners",
  "describe",
  "is_learned",
  "is_oracle",
  "learner",
  "make",
  "register",
  "register_installed",
  "training_summary",
]
