"""What every softbench task shares: actions in [-1, 1], a randomised start, pose observations
and a reward in [0, 1] from ``dm_control.utils.rewards.tolerance`` on position error.

Time convention: the observation before control step t holds the pose to reach by the end of
step t (``target``); the reward after step t scores the pose reached against that target.
"""

import collections

from dm_control.suite import base as suite_base
from dm_control.utils import rewards
from dm_env import specs
import numpy as np

from softbench.robots import base
from softbench.robots import physics as arm_physics
from softbench.suite import registry

INITIAL_ACTUATION = registry.INITIAL_ACTUATION  # Largest |action| of the start's random hold.
REWARD_TOLERANCE = 0.01  # Fraction of the arm length within which the reward is 1.
REWARD_MARGIN = 0.1  # Fraction of the arm length beyond the tolerance at which the reward is
# 0.1 (dm_control measures the margin from the bound: 0.1 at 11 % of the arm length).


class SoftArmTask(suite_base.Task):
  """Base task. Subclasses give ``targets_at`` (what to reach at a step) and the modules they
  score; this class runs actions, observations, the start and the reward.

  At the start of every episode the arm holds a random action, uniform in
  [-initial_actuation, initial_actuation], for one control period from rest, so that episodes of
  different seeds start from different poses (``initial_actuation=0`` starts at rest). That
  action is the first ``previous_action`` observation.
  """

  def __init__(
    self, robot: base.SoftArm, initial_actuation: float = INITIAL_ACTUATION, random=None
  ):
    if not 0.0 <= initial_actuation <= 1.0:
      raise ValueError(f"initial_actuation must lie in [0, 1], got {initial_actuation}")
    super().__init__(random=random)
    self.robot = robot
    self._initial_actuation = initial_actuation
    self._previous_action = None
    self._step = 0

  target_size = 6  # Entries of one module's target: position and orientation vector.

  def targets_at(self, step: int) -> np.ndarray:
    """(modules, 6 or 3): the poses to reach by the end of control step ``step``."""
    raise NotImplementedError

  @property
  def num_steps(self) -> int:
    """Control steps per episode."""
    raise NotImplementedError

  def reseed(self, seed: int) -> None:
    """Draws the following episodes' random starts (and reach points) from ``seed``, as a task
    built with ``random=seed`` does."""
    self._random = np.random.RandomState(seed)

  @property
  def steps_done(self) -> int:
    """Control steps taken in this episode; ``targets_at(steps_done)`` is the current target."""
    return self._step

  def scored_modules(self) -> tuple[int, ...]:
    """1-based modules whose poses ``targets_at`` lists, in order."""
    raise NotImplementedError

  def action_spec(self, physics: arm_physics.SoftArmPhysics) -> specs.BoundedArray:
    return specs.BoundedArray((physics.action_dim,), np.float64, -1.0, 1.0, name="action")

  @property
  def holds_initial_action(self) -> bool:
    """Whether an episode starts by holding ``start_episode``'s action for one control period
    from rest (False: it starts at rest)."""
    return self._initial_actuation > 0

  def start_episode(self) -> np.ndarray:
    """Draws this episode's randomness and returns the action held from rest before it (its
    first ``previous_action``); ``initialize_episode`` then holds it on the physics, a batch of
    arms (``softbench.envs.vector``) on its own, and both call ``episode_started``. A task
    overrides these two, not ``initialize_episode``, so that it also runs in a batch."""
    self._step = 0
    size = self._initial_actuation
    self._previous_action = self.random.uniform(-size, size, self.robot.action_dim)
    return self._previous_action.copy()

  def initialize_episode(self, physics: arm_physics.SoftArmPhysics) -> None:
    action = self.start_episode()
    if self.holds_initial_action:
      physics.set_action(action)
      physics.step(int(round(self.robot.control_timestep / physics.timestep())))
      physics.data.time = 0.0
    self.episode_started(physics.module_poses())

  def episode_started(self, poses: np.ndarray) -> None:
    """Called with the modules' poses (num_modules, 6) once the episode's start is reached."""

  def before_step(self, action: np.ndarray, physics: arm_physics.SoftArmPhysics) -> None:
    physics.set_action(action)
    self.take_action(action)

  def take_action(self, action: np.ndarray) -> None:
    """Notes the action of the step about to run (the next ``previous_action``)."""
    self._previous_action = np.array(action, dtype=float)

  def after_step(self, physics: arm_physics.SoftArmPhysics | None = None) -> None:
    self._step += 1

  def observation_spec(self, physics: arm_physics.SoftArmPhysics) -> collections.OrderedDict:
    modules = (len(self.scored_modules()), self.target_size)
    return collections.OrderedDict(
      poses=specs.Array((physics.num_modules, 6), np.float64, name="poses"),
      target=specs.Array(modules, np.float64, name="target"),
      previous_action=specs.BoundedArray(
        (physics.action_dim,), np.float64, -1.0, 1.0, name="previous_action"
      ),
    )

  def get_termination(self, physics: arm_physics.SoftArmPhysics) -> float | None:
    return 1.0 if self._step >= self.num_steps else None

  def get_observation(self, physics: arm_physics.SoftArmPhysics) -> collections.OrderedDict:
    return self.observation_from(physics.module_poses())

  def observation_from(self, poses: np.ndarray) -> collections.OrderedDict:
    """The observation when the arm's modules are at ``poses`` (num_modules, 6)."""
    observation = collections.OrderedDict()
    observation["poses"] = np.array(poses, dtype=np.float64)
    observation["target"] = self.targets_at(self._step)
    observation["previous_action"] = self._previous_action.copy()
    return observation

  def get_reward(self, physics: arm_physics.SoftArmPhysics) -> float:
    return self.reward_from(physics.module_poses())

  def reward_from(self, poses: np.ndarray) -> float:
    """Mean over scored modules of a tolerance reward on the distance of ``poses``
    (num_modules, 6), reached by the step just taken, to that step's target."""
    achieved = np.asarray(poses)[np.array(self.scored_modules()) - 1, :3]
    return float(position_reward(achieved, self.targets_at(self._step - 1), self.robot.length))


def position_reward(achieved: np.ndarray, target: np.ndarray, length: float) -> np.ndarray:
  """``SoftArmTask.reward_from``'s reward of reached positions ``achieved`` (..., scored, 3)
  against ``target`` (..., scored, 3 or 6) on an arm ``length`` (m) long, over any leading axes
  (the arms of a batch)."""
  distance = np.linalg.norm(achieved - target[..., :3], axis=-1)
  return np.mean(
    rewards.tolerance(
      distance,
      bounds=(0.0, REWARD_TOLERANCE * length),
      margin=REWARD_MARGIN * length,
      sigmoid="long_tail",
    ),
    axis=-1,
  )
