"""An example task for the registry test: hold every module at the pose it starts from. With one
registry line (``test_registries.py``) it is a task of the suite, scored and run like the others."""

import numpy as np

from softbench.suite import base

HOLD_STEPS = 20  # Control steps per episode.


class Hold(base.SoftArmTask):
  """Keep every module's pose where the random start left it."""

  def __init__(
    self, robot, steps: int = HOLD_STEPS, initial_actuation=base.INITIAL_ACTUATION, random=None
  ):
    super().__init__(robot, initial_actuation, random)
    self._steps, self._start = steps, None

  @property
  def num_steps(self) -> int:
    return self._steps

  def scored_modules(self) -> tuple[int, ...]:
    return tuple(range(1, self.robot.num_modules + 1))

  def initialize_episode(self, physics) -> None:
    super().initialize_episode(physics)
    self._start = physics.module_poses().copy()

  def targets_at(self, step: int) -> np.ndarray:
    return self._start.copy()
