"""A user's own target trajectory: an array, or a ``.npy`` or ``.csv`` file, one target per row.

A row lists every module's target pose in module order: tip position (m, world frame, the base
at the origin and the arm hanging along -z) then unit orientation vector, so a row of an
N-module arm has 6N numbers. A ``.csv`` file has no header; lines starting with ``#`` are
comments. An array may also be given as (steps, N, 6).

A trajectory may give only part of the target (``Given``, e.g. ``"1,3"`` or ``"2:position"``):
then a row lists, for each given module in ascending order, its tip position and, unless the
mask says ``:position``, its unit orientation vector; the other modules are free.
"""

import dataclasses
import math
import os
import pathlib
import re
import warnings

import numpy as np

from softbench import storage
from softbench.robots import base
from softbench.robots import recorder

UNIT_TOLERANCE = 1e-3  # Largest accepted | |orientation vector| - 1 |.
REACH_FACTOR = 2.0  # A target position lies within this many arm lengths of the base; farther
# is no place the arm can mean (1e300 once ran every episode, then failed writing the record).
POSITION_SUFFIX = ":position"  # Ends a mask that gives positions only.
POSITION_SIZE = 3  # Entries of a position-only target (m).
MAX_TRAJECTORY_STEPS = 1_000_000  # Rows (targets) of a trajectory file, checked in an .npy's
# header before loading: 11.6 days of a tendon arm's 1 s control period.
_MODULE_LIST = re.compile(r"\s*[0-9]+\s*(,\s*[0-9]+\s*)*")


@dataclasses.dataclass(frozen=True)
class Given:
  """Which part of the target a trajectory gives: some modules (1-based, ascending), with or
  without their orientation vectors. Text form: ``"1,3"`` (pose), ``"2:position"``."""

  modules: tuple[int, ...]
  orientation: bool = True

  def __post_init__(self):
    modules = self.modules
    if not isinstance(modules, tuple) or not modules:
      raise ValueError(f"given modules must be a non-empty tuple, got {modules!r}")
    if not all(isinstance(k, int) and not isinstance(k, bool) and k >= 1 for k in modules):
      raise ValueError(f"given modules must be 1-based module numbers, got {modules!r}")
    if len(set(modules)) != len(modules):
      raise ValueError(f"given modules must not repeat, got {_join(modules)}")
    if list(modules) != sorted(modules):
      raise ValueError(f"given modules must be in ascending order, got {_join(modules)}")
    if not isinstance(self.orientation, bool):
      raise ValueError(f"given orientation must be True or False, got {self.orientation!r}")

  @classmethod
  def of_target(cls, modules_from_zero: np.ndarray, target: np.ndarray) -> "Given":
    """The part a target of shape (len(modules), 3 or 6) gives of 0-based ``modules_from_zero``
    (an agent's scored modules): positions only where it has 3 columns."""
    return cls(
      tuple(int(module) + 1 for module in modules_from_zero), target.shape[1] == recorder.POSE_SIZE
    )

  @classmethod
  def parse(cls, text: str, robot: base.SoftArm) -> "Given":
    """The mask of ``text``: modules separated by commas, then ``:position`` for positions only.

    Raises:
      ValueError: malformed text, a module outside 1..num_modules or a repeated one (one line).
    """
    if not isinstance(text, str):
      raise ValueError(f"given must be text such as '1,3' or '2:position', got {text!r}")
    listed = text.strip()
    orientation = not listed.endswith(POSITION_SUFFIX)
    if not orientation:
      listed = listed[: -len(POSITION_SUFFIX)]
    if not _MODULE_LIST.fullmatch(listed):
      raise ValueError(
        f"given must list modules separated by commas, optionally followed by "
        f"'{POSITION_SUFFIX}' (e.g. '1,3' or '2:position'), got {text!r}"
      )
    modules = tuple(int(k) for k in listed.split(","))
    for module in modules:
      _check_module(module, robot)
    return cls(modules, orientation)

  @classmethod
  def whole(cls, robot: base.SoftArm) -> "Given":
    """Every module of ``robot``, with orientation: the whole target."""
    return cls(tuple(range(1, robot.num_modules + 1)), True)

  def check(self, robot: base.SoftArm) -> "Given":
    """This mask, if every module is one of ``robot``'s.

    Raises:
      ValueError: a module beyond ``robot.num_modules`` (one line).
    """
    _check_module(self.modules[-1], robot)
    return self

  @property
  def size(self) -> int:
    """Entries per given module: 6 (position, orientation) or 3 (position)."""
    return recorder.POSE_SIZE if self.orientation else POSITION_SIZE

  @property
  def text(self) -> str:
    """The text form, as ``parse`` reads it."""
    return _join(self.modules) + ("" if self.orientation else POSITION_SUFFIX)

  @property
  def indices(self) -> list[int]:
    """The given modules' 0-based indices."""
    return [module - 1 for module in self.modules]

  def part(self, poses: np.ndarray) -> np.ndarray:
    """The given entries of whole poses (..., num_modules, 6): (..., len(modules), size)."""
    return np.asarray(poses)[..., self.indices, : self.size]


def _check_module(module: int, robot: base.SoftArm) -> None:
  if not 1 <= module <= robot.num_modules:
    raise ValueError(
      f"given module {module} is not a module of {robot.name} (1 to {robot.num_modules})"
    )


def _join(modules) -> str:
  return ",".join(str(k) for k in modules)


def as_given(given, robot: base.SoftArm) -> Given | None:
  """``given`` (None, a ``Given`` or its text) as a ``Given`` checked against ``robot``.

  Raises:
    ValueError: malformed text, a module ``robot`` lacks, or another type (one line).
  """
  if given is None:
    return None
  if isinstance(given, Given):
    return given.check(robot)
  if isinstance(given, str):
    return Given.parse(given, robot)
  raise ValueError(f"given must be None, a Given or text such as '2:position', got {given!r}")


def leaves_part_out(robot: base.SoftArm, options: dict) -> bool:
  """Whether task ``custom`` with ``options`` gives only part of ``robot``'s pose (its
  ``TaskEntry.partial_targets``)."""
  return as_given(options.get("given"), robot) not in (None, Given.whole(robot))


def _read(path: pathlib.Path) -> np.ndarray:
  try:  # A FIFO would wait for a writer forever: named as what it is.
    storage.check_regular_file(path, "trajectory file")
  except FileNotFoundError:
    raise ValueError(f"trajectory file {path} does not exist") from None
  try:
    if path.suffix == ".npy":
      _check_npy_header(path)
      return np.load(path, allow_pickle=False)
    if path.suffix == ".csv":
      with warnings.catch_warnings():  # An empty file: refused below, with the expected shape.
        warnings.simplefilter("ignore", UserWarning)
        return np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
  except (OSError, ValueError, EOFError, MemoryError) as error:
    raise ValueError(f"trajectory file {path} is unreadable: {str(error).splitlines()[0]}")
  raise ValueError(f"trajectory file {path} must be .npy or .csv")


_NPY_HEADER_READERS = {
  (1, 0): np.lib.format.read_array_header_1_0,
  (2, 0): np.lib.format.read_array_header_2_0,
}


def _check_npy_header(path: pathlib.Path) -> None:
  """Refuses an .npy file from its header, before its array is loaded: more than
  ``MAX_TRAJECTORY_STEPS`` rows, or more bytes than the file holds (a header claiming shape
  (1e11, 6) made numpy ask for 4.8 TB). Other header versions are left to ``np.load``.

  Raises:
    ValueError: either (one line).
  """
  with open(path, "rb") as file:
    version = np.lib.format.read_magic(file)
    if version not in _NPY_HEADER_READERS:
      return
    shape, _, dtype = _NPY_HEADER_READERS[version](file)
    data_bytes = os.fstat(file.fileno()).st_size - file.tell()
  if shape and shape[0] > MAX_TRAJECTORY_STEPS:
    raise ValueError(f"its header claims {shape[0]:,} rows; at most {MAX_TRAJECTORY_STEPS:,}")
  if math.prod(shape) * dtype.itemsize > data_bytes:
    raise ValueError(f"its header claims shape {shape}, more than the file's {data_bytes:,} bytes")


def load_trajectory(source, robot: base.SoftArm, given: Given | str | None = None) -> np.ndarray:
  """Target poses (steps, num_modules, 6) from an array or a file path; with ``given``, only the
  given part: (steps, len(given.modules), given.size).

  Raises:
    ValueError: unreadable file, wrong shape (the message names the expected one), non-finite
      values, a position farther than ``REACH_FACTOR`` arm lengths from the base, given
      orientation vectors that are not unit length, or a malformed ``given``.
  """
  mask = as_given(given, robot)
  if mask is None:
    modules, size = robot.num_modules, recorder.POSE_SIZE
    expected = (
      f"(steps, {size * modules}): per row, each of the {modules} module(s)' tip position "
      f"(m) and unit orientation vector"
    )
  else:
    modules, size = len(mask.modules), mask.size
    entries = (
      "tip position (m) and unit orientation vector" if mask.orientation else "tip position (m)"
    )
    expected = (
      f"(steps, {size * modules}): per row, the {entries} of given module(s) {_join(mask.modules)}"
    )
  if isinstance(source, (str, pathlib.Path)):
    array = _read(pathlib.Path(source))
  else:
    array = np.asarray(source)
  if not np.issubdtype(array.dtype, np.number) or np.iscomplexobj(array):
    raise ValueError(f"trajectory must hold real numbers, got dtype {array.dtype}")
  array = array.astype(float)
  if array.ndim == 3 and array.shape[1:] == (modules, size):
    targets = array
  elif array.ndim == 2 and array.shape[1] == size * modules:
    targets = array.reshape(len(array), modules, size)
  else:
    raise ValueError(f"trajectory for {robot.name} must have shape {expected}; got {array.shape}")
  if len(targets) == 0:
    raise ValueError(f"trajectory for {robot.name} has no rows; expected shape {expected}")
  if len(targets) > MAX_TRAJECTORY_STEPS:
    raise ValueError(f"trajectory has {len(targets):,} rows; at most {MAX_TRAJECTORY_STEPS:,}")
  if not np.all(np.isfinite(targets)):
    raise ValueError("trajectory contains NaN or infinite values")
  if size == recorder.POSE_SIZE:
    _check_unit(targets[..., 3:])
  limit = REACH_FACTOR * robot.length
  far = np.abs(targets[..., :3]).max(axis=(1, 2)) > limit
  if np.any(far):
    raise ValueError(
      f"trajectory row {int(np.argmax(far))}: a target position lies more than "
      f"{limit * 1000:.0f} mm ({REACH_FACTOR:g} arm lengths) from the base of "
      f"{robot.name}; positions are in m"
    )
  return targets


def _check_unit(axes: np.ndarray) -> None:
  """Refuses orientation vectors (steps, modules, 3) that are not unit length."""
  if np.any(np.abs(axes) > 1.0 + UNIT_TOLERANCE):  # Before squaring: 1e300 overflows.
    row = int(np.argwhere(np.abs(axes) > 1.0 + UNIT_TOLERANCE)[0, 0])
    raise ValueError(f"trajectory row {row}: orientation vectors must have unit length")
  norms = np.linalg.norm(axes, axis=-1)
  if np.any(np.abs(norms - 1.0) > UNIT_TOLERANCE):
    row = int(np.argwhere(np.abs(norms - 1.0) > UNIT_TOLERANCE)[0, 0])
    raise ValueError(f"trajectory row {row}: orientation vectors must have unit length")
