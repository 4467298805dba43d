"""What every softbench agent is: a controller that reads a task's observations and returns an
action in [-1, 1]^action_dim, once per control step.

Observations are those of ``softbench.suite`` tasks (time convention in ``softbench.suite.base``):

  poses            (num_modules, 6)  every module's tip position (m) and orientation vector now
  target           (scored, 6 or 3)  the pose(s) to reach by the end of this step
  previous_action  (action_dim,)     the action held during the last step

An agent is built for one robot and seed by its registry entry (``softbench.agents.make``),
trained there if it learns; ``reset`` starts an episode of a given task.
"""

import abc
import dataclasses
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
  from softbench.robots.base import SoftArm


@dataclasses.dataclass(frozen=True)
class EpisodeInfo:
  """What an agent may know about the episode ahead: the task's name and scored modules."""

  task: str
  scored_modules: tuple[int, ...]


class Agent(abc.ABC):
  """A controller for one robot.

  ``uses_simulator`` marks model-based agents: before every episode the evaluation hands them
  the environment's physics (``bind``), which they may read (state, model) but must not change.
  Learned agents see observations only.
  """

  uses_simulator = False

  def __init__(self, robot: "SoftArm", seed: int):
    self.robot = robot
    self.seed = seed

  def bind(self, physics) -> None:
    """Gives a model-based agent the environment's ``SoftArmPhysics`` (read only)."""

  def reset(self, episode: EpisodeInfo) -> None:
    """Called before the first step of every episode."""

  @abc.abstractmethod
  def act(self, observation: dict) -> np.ndarray:
    """The action (action_dim,) in [-1, 1] for this control step."""

  def episode_state(self) -> dict[str, np.ndarray] | None:
    """What ``act`` carries from one step to the next beyond the observation, as arrays, so that
    an interrupted episode resumes where it stopped, bit for bit (``evaluation.run_episode``:
    worth it for an agent whose steps take seconds). None, the default: this agent's interrupted
    episodes start again."""
    return None

  def restore_episode_state(self, state: dict[str, np.ndarray]) -> None:
    """Takes back what ``episode_state`` gave, after ``reset`` (and ``bind``) of the same
    episode."""
    raise NotImplementedError(f"{type(self).__name__} keeps no episode state")
