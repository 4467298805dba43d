"""Tracking errors, as every softbench evaluation reports them (SPEC section 6).

A pose is a module tip's position (m) followed by its unit orientation vector (the arm axis at
the tip, world frame); position-only targets have 3 entries. For T control steps and N modules:

- position error: Euclidean distance, in mm;
- orientation error: angle between the achieved and target orientation vectors, in degrees;
- normalised tip error: position error / robot length x 100, in %.

``score`` gives each error per module (mean and standard deviation over the T steps, as the
paper's tables report them) and averaged over modules; ``Statistic.of(per_seed_values)`` then
gives the mean and standard deviation of a figure across seeds.
"""

import dataclasses
import math

import numpy as np

MM_PER_M = 1000.0
PERCENT = 100.0


def _split(poses: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
  poses = np.asarray(poses, dtype=float)
  if poses.shape[-1] not in (3, 6):
    raise ValueError(
      f"poses must end in 3 (position) or 6 (position, orientation) entries, "
      f"got shape {poses.shape}"
    )
  return poses[..., :3], (poses[..., 3:] if poses.shape[-1] == 6 else None)


def position_error_mm(achieved: np.ndarray, target: np.ndarray) -> np.ndarray:
  """Euclidean distance (mm) between achieved and target positions, over the last axis."""
  achieved_position, _ = _split(achieved)
  target_position, _ = _split(target)
  return np.linalg.norm(achieved_position - target_position, axis=-1) * MM_PER_M


def orientation_error_deg(achieved: np.ndarray, target: np.ndarray) -> np.ndarray:
  """Angle (deg) between achieved and target orientation vectors (normalised first)."""
  _, achieved_axis = _split(achieved)
  _, target_axis = _split(target)
  if achieved_axis is None or target_axis is None:
    raise ValueError("orientation error needs poses with 6 entries")
  achieved_axis = achieved_axis / np.linalg.norm(achieved_axis, axis=-1, keepdims=True)
  target_axis = target_axis / np.linalg.norm(target_axis, axis=-1, keepdims=True)
  # arctan2 of |cross| and dot is accurate at small angles, where arccos of the dot is not.
  sine = np.linalg.norm(np.cross(achieved_axis, target_axis), axis=-1)
  cosine = np.sum(achieved_axis * target_axis, axis=-1)
  return np.degrees(np.arctan2(sine, cosine))


def normalised_tip_error_percent(
  achieved: np.ndarray, target: np.ndarray, robot_length: float
) -> np.ndarray:
  """Position error as a percentage of the robot's length (m)."""
  if not robot_length > 0:
    raise ValueError(f"robot_length must be positive, got {robot_length}")
  return position_error_mm(achieved, target) / (robot_length * MM_PER_M) * PERCENT


def decimals_of(value: float) -> int:
  """How many decimals a figure is printed with: 2 from 1 up; below 1, enough for 3 significant
  digits (a reach error of 0.0094 mm is 0.00940, not 0.01)."""
  if value == 0 or abs(value) >= 1:
    return 2
  return max(2, 2 - math.floor(math.log10(abs(value))))


def number(value: float, decimals: int | None = None) -> str:
  """A figure as softbench prints it, with ``decimals`` (default: ``decimals_of(value)``)."""
  return f"{value:.{decimals_of(value) if decimals is None else decimals}f}"


def mean_and_std(mean: float, std: float) -> str:
  """``mean ± std``, both with the decimals of the mean."""
  decimals = decimals_of(mean)
  return f"{number(mean, decimals)} ± {number(std, decimals)}"


@dataclasses.dataclass(frozen=True)
class Statistic:
  """Mean and standard deviation (population, ddof 0) of a set of values."""

  mean: float
  std: float

  @classmethod
  def of(cls, values: np.ndarray) -> "Statistic":
    values = np.asarray(values, dtype=float)
    if values.size == 0:
      raise ValueError("no values to summarise")
    return cls(float(np.mean(values)), float(np.std(values)))


@dataclasses.dataclass(frozen=True)
class TrackingScore:
  """Errors of one episode: per module (over time) and averaged over modules.

  ``orientation_deg`` is empty for position-only targets.
  """

  position_mm: tuple[Statistic, ...]
  orientation_deg: tuple[Statistic, ...]
  normalised_tip_percent: tuple[Statistic, ...]

  def average(self, metric: str) -> Statistic:
    """Mean over modules of the per-module means and standard deviations of ``metric``."""
    per_module = getattr(self, metric)
    if not per_module:
      raise ValueError(f"{metric} was not measured")
    return Statistic(
      float(np.mean([s.mean for s in per_module])), float(np.mean([s.std for s in per_module]))
    )


def score(achieved: np.ndarray, target: np.ndarray, robot_length: float) -> TrackingScore:
  """Scores achieved against target poses, both (T, N, 6) or (T, N, 3) (target may be (T, N, 3)
  while achieved has 6 entries: position only)."""
  achieved = np.asarray(achieved, dtype=float)
  target = np.asarray(target, dtype=float)
  if achieved.ndim != 3 or target.ndim != 3 or achieved.shape[:2] != target.shape[:2]:
    raise ValueError(
      f"achieved and target must be (steps, modules, pose) with the same steps and "
      f"modules, got {achieved.shape} and {target.shape}"
    )
  per_module = lambda errors: tuple(Statistic.of(errors[:, k]) for k in range(errors.shape[1]))
  position_only = target.shape[-1] == 3
  achieved_compared = achieved[..., :3] if position_only else achieved
  return TrackingScore(
    position_mm=per_module(position_error_mm(achieved_compared, target)),
    orientation_deg=() if position_only else per_module(orientation_error_deg(achieved, target)),
    normalised_tip_percent=per_module(
      normalised_tip_error_percent(achieved_compared, target, robot_length)
    ),
  )
