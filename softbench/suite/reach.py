"""Reaching: bring one module's tip to a virtual point, position only (paper: module 2).

The point is reachable by construction: the tip position of that module after the arm holds a
random action (uniform in [-1, 1] for every entry, drawn from the task's seed) for
``TARGET_SETTLE_SECONDS`` from rest.
"""

import numpy as np

from softbench.robots import base as robot_base
from softbench.robots import recorder
from softbench.suite import base

REACH_SECONDS = 10.0  # (s) Episode duration.
TARGET_SETTLE_SECONDS = 3.0  # (s) Time the target-defining action is held; longer than every
# registered robot's settling time (tendon-5 0.72 s, pneumatic-433 1.39 s).
DEFAULT_MODULE = 2  # The paper's reaching experiment moves module 2 (module 1 on a 1-module arm).


def check_module(robot: robot_base.SoftArm, module: int | None) -> int:
  """The module that reaches: ``module``, or ``DEFAULT_MODULE`` if None.

  Raises:
    ValueError: ``module`` is not one of the robot's modules (one line).
  """
  module = min(DEFAULT_MODULE, robot.num_modules) if module is None else module
  is_index = isinstance(module, int) and not isinstance(module, bool)
  if not is_index or not 1 <= module <= robot.num_modules:
    raise ValueError(f"module must be 1 to {robot.num_modules} for {robot.name}, got {module!r}")
  return module


class Reach(base.SoftArmTask):
  """Bring module ``module``'s tip to a random reachable point within ``steps`` control steps."""

  target_size = 3

  def __init__(
    self,
    robot: robot_base.SoftArm,
    module: int | None = None,
    steps: int | None = None,
    initial_actuation: float = base.INITIAL_ACTUATION,
    random=None,
  ):
    super().__init__(robot, initial_actuation, random)
    module = check_module(robot, module)
    default_steps = int(round(REACH_SECONDS / robot.control_timestep))
    steps = default_steps if steps is None else steps
    if not (isinstance(steps, int) and steps >= 1):
      raise ValueError(f"steps must be a positive integer, got {steps!r}")
    self.module = module
    self._num_steps = steps
    self._target = None

  @property
  def num_steps(self) -> int:
    return self._num_steps

  def start_episode(self) -> np.ndarray:
    action = self.random.uniform(-1.0, 1.0, self.robot.action_dim)
    holds = int(np.ceil(TARGET_SETTLE_SECONDS / self.robot.control_timestep))
    poses = recorder.from_rest(self.robot, np.tile(action, (holds, 1)))
    self._target = poses[-1, self.module - 1, :3].copy()
    return super().start_episode()

  def targets_at(self, step: int) -> np.ndarray:
    return self._target[None].copy()

  def scored_modules(self) -> tuple[int, ...]:
    return (self.module,)
