"""Trajectory tracking: every module follows a sequence of target poses, one per control step.

The targets come from a reference the robot traced itself (``references``; a task of them is one
function that ``tracking_task`` registers) or from the user (``trajectories``), who may give only
part of them (``trajectories.Given``: some modules, with or without orientation); only the given
modules are shown and scored. The episode lasts one control step per target.
"""

from typing import Callable

import numpy as np

from softbench.robots import base as robot_base
from softbench.suite import base
from softbench.suite import references
from softbench.suite import registry
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


def tracking_task(
  description: str,
  *,
  tags: tuple[str, ...] = ("benchmarking",),
  paper_robot: str = "tendon-3",
  planar: bool = True,
) -> Callable[[Callable], Callable]:
  """Registers the decorated function as the tracking task of its name: every module follows the
  poses the robot reaches when the function's actions drive it from rest (its reference,
  ``references.Shape``), one target per control step for ``length`` steps (``load``'s option,
  default ``references.REFERENCE_LENGTH``).

  The function is ``trace(length, **parameters)``, returning (length, 2) points of the planar
  actuation space in bend amplitudes (every module bent alike), or, with ``planar=False``,
  ``trace(robot, length, **parameters)`` returning the robot's actions (length, action_dim) in
  [-1, 1]. Each parameter needs a default (numbers, strings or lists of them): the cache key of
  the task's references hashes them, and no other task's. The task's tags are ``tags`` and
  ``tracking``; the function is returned unchanged.

  Raises:
    ValueError: the name is taken or malformed, the arguments are not as above, or the paper
      robot is unknown (one line).
  """

  def register(trace: Callable) -> Callable:
    shape = references.Shape(trace.__name__, trace, planar)
    registry.register(
      shape.name,
      registry.TaskEntry(
        build=_following(shape.name),
        tags=tuple(dict.fromkeys((*tags, "tracking"))),
        description=description,
        paper_robot=paper_robot,
        length_option="length",
        reference=shape,
      ),
    )
    return trace

  return register


def _following(shape: str) -> Callable[..., Tracking]:
  """The task that follows reference ``shape`` (``TaskEntry.build``)."""

  def build(
    robot: robot_base.SoftArm,
    length: int = references.REFERENCE_LENGTH,
    initial_actuation: float = base.INITIAL_ACTUATION,
    random=None,
  ) -> Tracking:
    targets = references.reference(robot, shape, length).targets
    return Tracking(robot, targets, initial_actuation=initial_actuation, random=random)

  return build
