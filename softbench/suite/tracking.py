"""Trajectory tracking: every module follows a sequence of target poses, one per control step.

The targets come from a reference the robot traced itself (``references``) or from the user
(``trajectories``). The episode lasts one control step per target.
"""

import numpy as np

from softbench.robots import base as robot_base
from softbench.suite import base


class Tracking(base.SoftArmTask):
  """Follow ``targets`` (steps, num_modules, 6) with every module."""

  def __init__(
    self,
    robot: robot_base.SoftArm,
    targets: np.ndarray,
    initial_actuation: float = base.INITIAL_ACTUATION,
    random=None,
  ):
    super().__init__(robot, initial_actuation, random)
    targets = np.asarray(targets, dtype=float)
    if targets.ndim != 3 or targets.shape[1:] != (robot.num_modules, 6) or len(targets) == 0:
      raise ValueError(f"targets must be (steps, {robot.num_modules}, 6), got {targets.shape}")
    self._targets = targets

  @property
  def num_steps(self) -> int:
    return len(self._targets)

  def targets_at(self, step: int) -> np.ndarray:
    # After the last step the observation repeats the last target.
    return self._targets[min(step, len(self._targets) - 1)].copy()

  def scored_modules(self) -> tuple[int, ...]:
    return tuple(range(1, self.robot.num_modules + 1))
