"""Trajectory tracking: every module follows a sequence of target poses, one per control step.

The targets come from a reference the robot traced itself (``references``; a task of them is one
function that ``registry.tracking_task`` registers) or from the user (``trajectories``), who may
give only part of them (``trajectories.Given``: some modules, with or without orientation); only
the given modules are shown and scored. The episode lasts one control step per target.
"""

import numpy as np

from softbench.robots import base as robot_base
from softbench.suite import base
from softbench.suite import references
from softbench.suite import trajectories


class Tracking(base.SoftArmTask):
  """Follow ``targets`` (steps, num_modules, 6) with every module, or, with ``given``, targets
  (steps, len(given.modules), given.size) with the given modules."""

  def __init__(
    self,
    robot: robot_base.SoftArm,
    targets: np.ndarray,
    initial_actuation: float = base.INITIAL_ACTUATION,
    random=None,
    given: trajectories.Given | str | None = None,
  ):
    super().__init__(robot, initial_actuation, random)
    given = trajectories.as_given(given, robot)
    self.given = trajectories.Given.whole(robot) if given is None else given
    self.target_size = self.given.size
    shape = (len(self.given.modules), self.given.size)
    targets = np.asarray(targets, dtype=float)
    if targets.ndim != 3 or targets.shape[1:] != shape or len(targets) == 0:
      raise ValueError(f"targets must be (steps, {shape[0]}, {shape[1]}), got {targets.shape}")
    self._targets = targets

  @property
  def num_steps(self) -> int:
    return len(self._targets)

  def targets_at(self, step: int) -> np.ndarray:
    # After the last step the observation repeats the last target.
    return self._targets[min(step, len(self._targets) - 1)].copy()

  def scored_modules(self) -> tuple[int, ...]:
    return self.given.modules


def following(
  robot: robot_base.SoftArm, shape: str, length: int, initial_actuation: float, random
) -> Tracking:
  """The task that follows reference ``shape`` (the build of ``registry.tracking_task``)."""
  targets = references.reference(robot, shape, length).targets
  return Tracking(robot, targets, initial_actuation=initial_actuation, random=random)


def custom(
  robot: robot_base.SoftArm,
  trajectory=None,
  given: trajectories.Given | str | None = None,
  initial_actuation: float = base.INITIAL_ACTUATION,
  random=None,
) -> Tracking:
  """Task ``custom``: follow the user's ``trajectory`` (an array or a .npy/.csv path), of which
  ``given`` says the part it gives."""
  if trajectory is None:
    raise ValueError(
      "task 'custom' needs a trajectory (trajectory=ARRAY_OR_PATH, or --trajectory FILE)"
    )
  mask = trajectories.as_given(given, robot)
  return Tracking(
    robot,
    trajectories.load_trajectory(trajectory, robot, mask),
    initial_actuation=initial_actuation,
    random=random,
    given=mask,
  )
