"""Example tasks: ``Hold`` keeps every module at the pose it starts from, and with one registry
line (``test_registries.py``) it is a task of the suite, scored and run like the others; a
figure eight is a tracking task from one decorated function (``register_figure_eight``)."""

import numpy as np

from softbench import suite
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

  def episode_started(self, poses: np.ndarray) -> None:
    self._start = poses.copy()

  def targets_at(self, step: int) -> np.ndarray:
    return self._start.copy()


FIGURE_EIGHT_SIZE = 0.8  # (bend amplitudes) Half the figure eight's width.
FIGURE_EIGHT_LAPS = 2


def register_figure_eight(laps: int = FIGURE_EIGHT_LAPS) -> str:
  """Registers tracking task ``figure_eight`` as a user's own module does, with one decorated
  function (here within a function, so that a test registers it when it needs it); its name."""

  @suite.tracking_task("follow a figure eight traced in actuation space")
  def figure_eight(length: int, size: float = FIGURE_EIGHT_SIZE, laps: int = laps) -> np.ndarray:
    """A lemniscate of Gerono, ``laps`` times from the centre: x = sin(a), y = sin(a) cos(a)."""
    angle = 2 * np.pi * laps * np.arange(1, length + 1) / length
    return size * np.stack([np.sin(angle), np.sin(angle) * np.cos(angle)], axis=-1)

  return figure_eight.__name__
