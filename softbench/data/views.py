"""What a learner sees of a babbling dataset, cut into training windows (SPEC sections 4, 5).

A ``View`` picks one learner's poses and actions, for any number of modules:

  View.end_effector(robot)  the last module's pose and every action (Exp1S).
  View.module(robot, k)     module k's pose and own actions, with the actions of modules 1 .. k-1
                            as ``preceding_actions`` (Exp2S, Exp2R); k counts from 1 at the base.
  View.module_reading_every_actuation(robot, k)
                            the same, with every other module's actions as ``preceding_actions``
                            (an analysis of what SMPL's forward models cannot see).
  View.whole_arm(robot)     every module's pose, flattened from the base, and every action
                            (centralised baselines).

``windows(data, view)`` splits the dataset into contiguous pieces (``softbench.data.splits``),
fits min-max normalisers on the training pieces only, and cuts each normalised piece into
``smpl.windows.BabblingWindows`` of ``SEQUENCE_LENGTH`` control steps (float32 tensors). The time
convention is that of ``smpl.windows``: pose index s comes before action s. A piece too short for
one window gives none.
"""

import dataclasses
import numbers

import numpy as np
import torch

from smpl import windows as smpl_windows
from softbench import robots
from softbench.data import dataset
from softbench.data import normalisation
from softbench.data import splits
from softbench.robots import recorder


@dataclasses.dataclass(frozen=True)
class View:
  """The poses and actions one learner sees.

  Attributes:
    name: e.g. ``end-effector``, ``module-2``, ``whole-arm``.
    pose_modules: Indices (from 0 at the base) of the modules whose poses it sees, in order.
    action_indices: Entries of the action vector it produces.
    preceding_action_indices: Entries of the action vector of the modules before its own.
  """

  name: str
  pose_modules: tuple[int, ...]
  action_indices: tuple[int, ...]
  preceding_action_indices: tuple[int, ...] = ()

  @classmethod
  def end_effector(cls, robot: robots.SoftArm) -> "View":
    return cls("end-effector", (robot.num_modules - 1,), tuple(range(robot.action_dim)))

  @classmethod
  def module(cls, robot: robots.SoftArm, module: int) -> "View":
    """Module ``module`` (1 at the base) of ``robot``."""
    if (
      isinstance(module, bool)
      or not isinstance(module, numbers.Integral)
      or not 1 <= module <= robot.num_modules
    ):
      raise ValueError(f"module must be 1 to {robot.num_modules} for {robot.name}, got {module!r}")
    slices = robot.module_action_slices()
    return cls(
      f"module-{module}",
      (module - 1,),
      _indices(slices[module - 1 : module]),
      _indices(slices[: module - 1]),
    )

  @classmethod
  def module_reading_every_actuation(cls, robot: robots.SoftArm, module: int) -> "View":
    """Module ``module``'s view whose forward model also reads the distal modules' actuation
    (every module's but its own, base first, then its own)."""
    own = cls.module(robot, module)
    others = tuple(index for index in range(robot.action_dim) if index not in own.action_indices)
    return dataclasses.replace(
      own, name=f"{own.name}-every-actuation", preceding_action_indices=others
    )

  @classmethod
  def whole_arm(cls, robot: robots.SoftArm) -> "View":
    return cls("whole-arm", tuple(range(robot.num_modules)), tuple(range(robot.action_dim)))

  @property
  def pose_size(self) -> int:
    return recorder.POSE_SIZE * len(self.pose_modules)

  @property
  def action_size(self) -> int:
    return len(self.action_indices)

  @property
  def preceding_action_size(self) -> int:
    return len(self.preceding_action_indices)

  def select(
    self, poses: np.ndarray, actions: np.ndarray
  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The view of poses (..., num_modules, 6) and actions (..., action_dim): its poses
    (..., pose_size), actions (..., action_size) and preceding actions."""
    seen = np.asarray(poses)[..., list(self.pose_modules), :]
    actions = np.asarray(actions)
    return (
      seen.reshape(seen.shape[:-2] + (self.pose_size,)),
      actions[..., list(self.action_indices)],
      actions[..., list(self.preceding_action_indices)],
    )


@dataclasses.dataclass(frozen=True, eq=False)
class SplitWindows:
  """Normalised windows of each split, and the normalisation fitted on the training split."""

  view: View
  train: smpl_windows.BabblingWindows
  validation: smpl_windows.BabblingWindows
  test: smpl_windows.BabblingWindows
  normalisation: normalisation.Normalisation


def windows(
  data: dataset.Dataset,
  view: View,
  window_length: int = smpl_windows.SEQUENCE_LENGTH,
  stride: int = 1,
  fractions: tuple[float, ...] = splits.FRACTIONS,
  fitted: normalisation.Normalisation | None = None,
) -> SplitWindows:
  """``view``'s windows of each split of ``data`` (see the module docstring), normalised with
  ``fitted`` if given (e.g. a trained controller's, to retrain it on new data) instead of
  statistics fitted on this dataset's training split.

  Raises:
    ValueError: the view does not fit the dataset, or a split holds no window.
  """
  if (
    max(view.pose_modules) >= data.num_modules
    or max(view.action_indices + view.preceding_action_indices) >= data.action_dim
  ):
    raise ValueError(
      f"view {view.name} does not fit {data.robot_name} ({data.num_modules} "
      f"modules, {data.action_dim} actions)"
    )
  recordings = {
    split: [view.select(*piece.recording(data)) for piece in pieces]
    for split, pieces in splits.split_pieces(data.episode_lengths, fractions).items()
  }

  def fit(part: int) -> normalisation.MinMaxNormaliser:
    return normalisation.MinMaxNormaliser.fit(
      np.concatenate([recording[part] for recording in recordings["train"]])
    )

  if fitted is None:
    fitted = normalisation.Normalisation(poses=fit(0), actions=fit(1), preceding_actions=fit(2))
  cut = {
    split: _cut(split, recordings[split], fitted, window_length, stride) for split in splits.SPLITS
  }
  return SplitWindows(view=view, normalisation=fitted, **cut)


def _indices(slices: list[slice]) -> tuple[int, ...]:
  return tuple(index for part in slices for index in range(part.start, part.stop))


def _tensor(values: np.ndarray) -> torch.Tensor:
  return torch.from_numpy(values.astype(np.float32))


def _with_unused_last(actions: np.ndarray) -> np.ndarray:
  """One action row per pose, as ``from_recording`` takes them; the last pose's is never read."""
  return np.concatenate([actions, np.zeros_like(actions[:1])])


def _cut(
  split: str,
  recordings: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
  fitted: normalisation.Normalisation,
  window_length: int,
  stride: int,
) -> smpl_windows.BabblingWindows:
  """Normalised windows of every piece long enough for one, concatenated."""
  batches = [
    smpl_windows.BabblingWindows.from_recording(
      _tensor(fitted.poses.normalise(poses)),
      _tensor(_with_unused_last(fitted.actions.normalise(actions))),
      _tensor(_with_unused_last(fitted.preceding_actions.normalise(preceding))),
      window_length,
      stride,
    )
    for poses, actions, preceding in recordings
    if len(actions) > window_length
  ]
  if not batches:
    samples = sum(len(actions) for _, actions, _ in recordings)
    raise ValueError(
      f"the {split} split ({samples} samples) holds no window of "
      f"{window_length} steps; collect more samples"
    )
  return smpl_windows.BabblingWindows(
    *(
      torch.cat([getattr(batch, field) for batch in batches])
      for field in ("poses", "actions", "preceding_actions")
    )
  )
