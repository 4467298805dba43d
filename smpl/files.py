"""Files without torch, for softbench and smpl alike: the one atomic writer, the one reading rule
of every cache (`read_cached`), and one-line messages."""

from __future__ import annotations

import os
from pathlib import Path
import re
import shutil
import tempfile
from typing import Callable
from typing import TypeVar
import warnings

T = TypeVar("T")
_ESCAPE_SEQUENCE = re.compile(r"\x1b\[[0-9;]*m")
"""A terminal colour code, as torch puts in some of its messages."""


_FILE_MODE = 0o666
"""What `open()` requests for a new file; the umask takes its share."""


def write_atomically(path: str | os.PathLike[str], content: str | bytes) -> None:
  """Writes `content` (text or bytes) to `path` through a temporary file in its folder and a
  rename, so that a reader sees the old file or the new one, never half of one.

  The file gets the permissions a plain `open` would give (0666 less the umask), not the
  owner-only mode of the temporary file, so that everyone sharing a data home reads every
  file alike. A failed write (a full disk, `path` a folder) removes the temporary file and
  raises its error, naming `path`.
  """
  path = Path(path)
  path.parent.mkdir(parents=True, exist_ok=True)
  handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
  try:
    with os.fdopen(handle, "wb" if isinstance(content, bytes) else "w") as file:
      file.write(content)
      file.flush()
      os.fsync(file.fileno())
    os.chmod(temporary, _FILE_MODE & ~_umask())
    os.replace(temporary, path)
  except OSError as error:
    Path(temporary).unlink(missing_ok=True)
    if error.filename is None or str(error.filename) == temporary:  # Name the real file.
      raise type(error)(error.errno, error.strerror, str(path)) from error
    raise
  except BaseException:
    Path(temporary).unlink(missing_ok=True)
    raise


def _umask() -> int:
  current = os.umask(0)
  os.umask(current)
  return current


def first_line(error: BaseException) -> str:
  """An exception's message on one line (its first, without terminal colour codes)."""
  lines = _ESCAPE_SEQUENCE.sub("", str(error)).strip().splitlines()
  return lines[0].strip() if lines else type(error).__name__


class CorruptFileWarning(UserWarning):
  """A cached file (a dataset, chunk, reference, checkpoint, saved episode, ...) could not be
  used; it is made again."""


def read_cached(
  path: Path,
  read: Callable[[Path], T],
  what: str,
  remedy: str,
  companions: tuple[Path, ...] = (),
) -> T | None:
  """`read(path)` for the cache file `path`, or None when nothing is there.

  The one reading rule of every cache: whatever `read` raises (a failed hash check, a zip
  whose flags name an unknown compression, a folder where the file belongs, ...) means the
  file is damaged. One `CorruptFileWarning` names it and says what happens instead (`remedy`,
  e.g. "collecting it again"), the file (or folder) is removed, since the cache owns its paths
  and writes the file anew there, and None is returned for the caller to make it again. The
  `companions` of a file written in several parts (a dataset's arrays beside its manifest) go
  with it.
  """
  path = Path(path)
  if not os.path.lexists(path):
    return None
  try:
    return read(path)
  except Exception as error:  # pylint: disable=broad-except  (the rule: any failure is damage)
    reason = first_line(error).removeprefix(f"{path}: ")  # Named once.
    warnings.warn(
      f"{path}: unreadable {what} ({type(error).__name__}: {reason}); {remedy}",
      CorruptFileWarning,
      stacklevel=2,
    )
    for damaged in (path, *companions):
      discard(Path(damaged))
    return None


def write_cache_file(path: Path, content: str | bytes, what: str) -> None:
  """`write_atomically` for a cache file: anything but a file standing at `path` (a folder) is
  damage, as for `read_cached`: reported, removed, and the file written in its place."""
  path = Path(path)
  if os.path.lexists(path) and not path.is_file():
    warnings.warn(
      f"{path}: not a file where the {what} belongs; removing it",
      CorruptFileWarning,
      stacklevel=2,
    )
    discard(path)
  write_atomically(path, content)


def discard(path: Path) -> None:
  """Removes a damaged cache file, or a folder or link standing where one belongs."""
  if path.is_dir() and not path.is_symlink():
    shutil.rmtree(path, ignore_errors=True)
  else:
    path.unlink(missing_ok=True)
