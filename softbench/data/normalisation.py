"""Min-max normalisation of features to [-1, 1], fitted on the training split only (SPEC 4).

Statistics round-trip through plain arrays (``to_arrays``, ``from_arrays``), as checkpoints store
them. Data outside the training range map outside [-1, 1]; they are not clipped.
"""

import dataclasses

import numpy as np

CONSTANT_RANGE = 1e-12  # Features whose training range is below this are centred, not scaled.


@dataclasses.dataclass(frozen=True, eq=False)
class MinMaxNormaliser:
  """Maps each feature's training range [minimum, maximum] onto [-1, 1].

  Attributes:
    minimum: (features,) training minimum of each feature.
    maximum: (features,) training maximum of each feature.
  """

  minimum: np.ndarray
  maximum: np.ndarray

  def __post_init__(self):
    if (
      np.ndim(self.minimum) != 1
      or np.shape(self.minimum) != np.shape(self.maximum)
      or np.any(np.asarray(self.maximum) < np.asarray(self.minimum))
    ):
      raise ValueError("minimum and maximum must be 1-D, of one shape, minimum <= maximum")

  @classmethod
  def fit(cls, data: np.ndarray) -> "MinMaxNormaliser":
    """Statistics of ``data`` (..., features) over all leading axes."""
    data = np.asarray(data, dtype=float)
    rows = data.reshape(int(np.prod(data.shape[:-1])), data.shape[-1])
    if len(rows) == 0:
      raise ValueError("cannot fit a normaliser to no data")
    return cls(rows.min(axis=0), rows.max(axis=0))

  @property
  def features(self) -> int:
    return len(self.minimum)

  @property
  def centre(self) -> np.ndarray:
    """(features,) the middle of each training range; ``normalise`` is (x - centre) / half_range."""
    return (np.asarray(self.maximum) + np.asarray(self.minimum)) / 2

  @property
  def half_range(self) -> np.ndarray:
    """(features,) half of each training range (1 where the range is constant)."""
    half_range = (np.asarray(self.maximum) - np.asarray(self.minimum)) / 2
    return np.where(half_range < CONSTANT_RANGE / 2, 1.0, half_range)

  def normalise(self, values: np.ndarray) -> np.ndarray:
    """``values`` (..., features) in normalised units."""
    return (np.asarray(values, dtype=float) - self.centre) / self.half_range

  def denormalise(self, values: np.ndarray) -> np.ndarray:
    """The inverse of ``normalise``."""
    return np.asarray(values, dtype=float) * self.half_range + self.centre

  def to_arrays(self, prefix: str = "") -> dict[str, np.ndarray]:
    return {
      f"{prefix}minimum": np.array(self.minimum, dtype=float),
      f"{prefix}maximum": np.array(self.maximum, dtype=float),
    }

  @classmethod
  def from_arrays(cls, arrays: dict[str, np.ndarray], prefix: str = "") -> "MinMaxNormaliser":
    return cls(
      np.array(arrays[f"{prefix}minimum"], dtype=float),
      np.array(arrays[f"{prefix}maximum"], dtype=float),
    )


@dataclasses.dataclass(frozen=True, eq=False)
class Normalisation:
  """The normalisers of one learner's inputs: its poses, its actions, preceding modules' actions
  (no features when there are none)."""

  poses: MinMaxNormaliser
  actions: MinMaxNormaliser
  preceding_actions: MinMaxNormaliser

  def to_arrays(self) -> dict[str, np.ndarray]:
    """Flat named arrays, e.g. for ``smpl.checkpoint.save_checkpoint(normalisation=...)``."""
    return {
      name: array
      for field in dataclasses.fields(self)
      for name, array in getattr(self, field.name).to_arrays(f"{field.name}_").items()
    }

  @classmethod
  def from_arrays(cls, arrays: dict[str, np.ndarray]) -> "Normalisation":
    return cls(
      **{
        field.name: MinMaxNormaliser.from_arrays(arrays, f"{field.name}_")
        for field in dataclasses.fields(cls)
      }
    )
