"""A user's own target trajectory: an array, or a ``.npy`` or ``.csv`` file, one target per row.

A row lists every module's target pose in module order: tip position (m, world frame, the base
at the origin and the arm hanging along -z) then unit orientation vector, so a row of an
N-module arm has 6N numbers. A ``.csv`` file has no header; lines starting with ``#`` are
comments. An array may also be given as (steps, N, 6).
"""

import pathlib
import warnings

import numpy as np

from softbench.robots import base

UNIT_TOLERANCE = 1e-3  # Largest accepted | |orientation vector| - 1 |.
REACH_FACTOR = 2.0  # A target position lies within this many arm lengths of the base; farther
# is no place the arm can mean (1e300 once ran every episode, then failed writing the record).


def _read(path: pathlib.Path) -> np.ndarray:
  if path.is_dir():
    raise ValueError(f"trajectory file {path} is a folder")
  if not path.is_file():
    raise ValueError(f"trajectory file {path} does not exist")
  try:
    if path.suffix == ".npy":
      return np.load(path, allow_pickle=False)
    if path.suffix == ".csv":
      with warnings.catch_warnings():  # An empty file: refused below, with the expected shape.
        warnings.simplefilter("ignore", UserWarning)
        return np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
  except (OSError, ValueError, EOFError) as error:
    raise ValueError(f"trajectory file {path} is unreadable: {str(error).splitlines()[0]}")
  raise ValueError(f"trajectory file {path} must be .npy or .csv")


def load_trajectory(source, robot: base.SoftArm) -> np.ndarray:
  """Target poses (steps, num_modules, 6) from an array or a file path.

  Raises:
    ValueError: unreadable file, wrong shape (the message names the expected one), non-finite
      values, a position farther than ``REACH_FACTOR`` arm lengths from the base, or
      orientation vectors that are not unit length.
  """
  modules = robot.num_modules
  expected = (
    f"(steps, {6 * modules}): per row, each of the {modules} module(s)' tip position "
    f"(m) and unit orientation vector"
  )
  if isinstance(source, (str, pathlib.Path)):
    array = _read(pathlib.Path(source))
  else:
    array = np.asarray(source)
  if not np.issubdtype(array.dtype, np.number) or np.iscomplexobj(array):
    raise ValueError(f"trajectory must hold real numbers, got dtype {array.dtype}")
  array = array.astype(float)
  if array.ndim == 3 and array.shape[1:] == (modules, 6):
    targets = array
  elif array.ndim == 2 and array.shape[1] == 6 * modules:
    targets = array.reshape(len(array), modules, 6)
  else:
    raise ValueError(f"trajectory for {robot.name} must have shape {expected}; got {array.shape}")
  if len(targets) == 0:
    raise ValueError(f"trajectory for {robot.name} has no rows; expected shape {expected}")
  if not np.all(np.isfinite(targets)):
    raise ValueError("trajectory contains NaN or infinite values")
  if np.any(np.abs(targets[..., 3:]) > 1.0 + UNIT_TOLERANCE):  # Before squaring: 1e300 overflows.
    row = int(np.argwhere(np.abs(targets[..., 3:]) > 1.0 + UNIT_TOLERANCE)[0, 0])
    raise ValueError(f"trajectory row {row}: orientation vectors must have unit length")
  norms = np.linalg.norm(targets[..., 3:], axis=-1)
  if np.any(np.abs(norms - 1.0) > UNIT_TOLERANCE):
    row = int(np.argwhere(np.abs(norms - 1.0) > UNIT_TOLERANCE)[0, 0])
    raise ValueError(f"trajectory row {row}: orientation vectors must have unit length")
  limit = REACH_FACTOR * robot.length
  far = np.abs(targets[..., :3]).max(axis=(1, 2)) > limit
  if np.any(far):
    raise ValueError(
      f"trajectory row {int(np.argmax(far))}: a target position lies more than "
      f"{limit * 1000:.0f} mm ({REACH_FACTOR:g} arm lengths) from the base of "
      f"{robot.name}; positions are in m"
    )
  return targets
