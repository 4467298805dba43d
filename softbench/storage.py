"""Where softbench keeps its files, and how it writes them: atomically, with content hashes.

The data home is ``$SOFTBENCH_HOME`` if set, else ``$XDG_CACHE_HOME/softbench`` (by default
``~/.cache/softbench``). Every file goes through a temporary file in the same folder and an
``os.replace``, so a reader sees the old file or the new one, never half of one; a file that
must not replace another (a result record) goes in with a hard link instead (``write_new``).
"""

from collections.abc import Callable
from collections.abc import Iterator
import contextlib
import dataclasses
import fcntl
import hashlib
import io
import os
import pathlib
import secrets
import stat
import sys
import tempfile
from typing import TypeVar

import numpy as np

from smpl import files
from smpl.files import CorruptFileWarning  # noqa: F401
from smpl.files import first_line  # noqa: F401
from smpl.files import read_cached  # noqa: F401
from smpl.files import write_cache_file  # noqa: F401  (softbench's caches write through it)

HOME_VARIABLE = "SOFTBENCH_HOME"
CACHE_VARIABLE = "XDG_CACHE_HOME"  # Its softbench/ is the data home where HOME_VARIABLE is unset.
LOCKS_FOLDER = ".locks"  # In the data home: ``made_alone``'s lock files.
_HELD: set[pathlib.Path] = set()  # The lock files this process holds (``made_alone`` nests).
T = TypeVar("T")


def softbench_home() -> pathlib.Path:
  """The folder under which datasets, reference trajectories and checkpoints are cached."""
  if os.environ.get(HOME_VARIABLE):
    return pathlib.Path(os.environ[HOME_VARIABLE]).expanduser()
  cache = os.environ.get(CACHE_VARIABLE) or pathlib.Path.home() / ".cache"
  return pathlib.Path(cache) / "softbench"


def write_atomically(path: pathlib.Path, content: str | bytes) -> None:
  """Writes ``content`` (text or bytes) to ``path`` through a temporary file and a rename, with
  the permissions of a plain ``open``; the one atomic writer of softbench and smpl
  (``smpl.files.write_atomically``). A failed write removes the temporary file and raises
  its error, naming ``path`` (a full disk says which file it could not write)."""
  files.write_atomically(path, content)


def write_new(path: pathlib.Path, content: str | bytes) -> bool:
  """Writes ``content`` to ``path`` unless something is there already, whole or not at all: a
  complete temporary file in the same folder is hard-linked to ``path`` (a link never replaces a
  file; a rename would). False, writing nothing, where ``path`` exists. Where the file system has
  no hard links, ``path`` is claimed empty (``O_EXCL``) and then replaced by the whole file."""
  path = pathlib.Path(path)
  temporary = path.with_name(f".{path.name}.{secrets.token_hex(4)}.new")
  try:
    write_atomically(temporary, content)
    try:
      os.link(temporary, path)
    except FileExistsError:
      return False
    except OSError:  # No hard links here (some network and FAT file systems).
      if not _claimed(path):
        return False
      os.replace(temporary, path)
  finally:
    temporary.unlink(missing_ok=True)
  return True


def _claimed(path: pathlib.Path) -> bool:
  """Whether this process created ``path``, empty; False where it exists."""
  try:
    os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
  except FileExistsError:
    return False
  return True


@contextlib.contextmanager
def made_alone(path: pathlib.Path, what: str, home: pathlib.Path | None = None) -> Iterator[None]:
  """Holds an exclusive lock on making ``path`` (a cache file or folder of the data home
  ``home``, by default ``softbench_home()``) for the block, so that processes sharing a data home
  do not train or collect the same thing at once: a second one waits, saying so in one line on
  stderr, and then finds it made (the caller reads the cache again inside the block). The lock
  (``flock``, released when its process ends, even killed) is a file in ``home/LOCKS_FOLDER``;
  where the file system cannot lock, the block runs unlocked, as before."""
  home = softbench_home() if home is None else pathlib.Path(home)
  try:
    name = path.resolve().relative_to(home.resolve()).as_posix().replace("/", "--")
  except ValueError:  # Outside the data home: named by its absolute path.
    name = hashlib.sha256(str(path.resolve()).encode()).hexdigest()[:16]
  lock_path = home / LOCKS_FOLDER / f"{name}.lock"
  if lock_path in _HELD:  # Held already by this process, further up the stack.
    yield
    return
  try:
    lock_path.parent.mkdir(parents=True, exist_ok=True)
    handle = open(lock_path, "a")  # noqa: SIM115  (closed below)
  except OSError:  # A read-only home: nothing is made there either, so nothing to guard.
    handle = None
  try:
    if handle is not None:
      _lock(handle, f"{what} {path.name}")
      _HELD.add(lock_path)
    yield
  finally:
    if handle is not None:
      _HELD.discard(lock_path)
      handle.close()  # Releases the lock.


def found_or_made(
  path: pathlib.Path,
  find: Callable[[], T | None],
  make: Callable[[], T],
  what: str,
  home: pathlib.Path | None = None,
) -> T:
  """``find()``'s cached thing at ``path``, else ``make()``'s, made under ``made_alone`` after
  finding once more (another process sharing the data home may have made it meanwhile)."""
  found = find()
  if found is not None:
    return found
  with made_alone(path, what, home):
    found = find()
    return found if found is not None else make()


def _lock(handle, making: str) -> None:
  """Takes ``handle``'s exclusive lock, waiting (and saying so) while another process holds it;
  nothing if the file system cannot lock."""
  try:
    fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
  except BlockingIOError:
    print(
      f"softbench: waiting for another process making the {making} (it holds the lock)",
      file=sys.stderr,
      flush=True,
    )
    fcntl.flock(handle, fcntl.LOCK_EX)
  except OSError:  # No locks on this file system (some network mounts).
    pass


def check_writable(path: str | os.PathLike, what: str, folder: bool = False) -> pathlib.Path:
  """``path`` as a ``Path`` if ``what`` (e.g. "video") can be written there: a file (or, with
  ``folder``, a folder of files) whose missing parent folders can be made. Checked before long
  work, so that it does not end in a failed write.

  A file must be a regular file or nothing: a link, a device or a FIFO there would be replaced
  (``--json /dev/stdout``, run as root, replaced the system's link). A folder may be a link to
  one.

  Raises:
    ValueError: ``path`` is not a folder where one is wanted, or not a regular file where a file
      is, a parent is a file, or there is no permission to write (one line).
  """
  path = pathlib.Path(path)
  try:
    mode = (os.stat if folder else os.lstat)(path).st_mode
  except OSError:  # Nothing there (or a folder that cannot be looked into: said below).
    mode = None
  if mode is not None and not (stat.S_ISDIR(mode) if folder else stat.S_ISREG(mode)):
    wanted = "a folder" if folder else "a regular file"
    raise ValueError(f"cannot write {what} {str(path)!r}: it is {file_kind(mode)}, not {wanted}")
  ancestor = path.absolute() if folder else path.absolute().parent
  while not ancestor.exists():
    ancestor = ancestor.parent
  if not ancestor.is_dir():
    raise ValueError(f"cannot write {what} {str(path)!r}: {str(ancestor)!r} is not a folder")
  if not os.access(ancestor, os.W_OK | os.X_OK):
    raise ValueError(
      f"cannot write {what} {str(path)!r}: no permission to write in {str(ancestor)!r}"
    )
  if not folder and path.exists() and not os.access(path, os.W_OK):
    raise ValueError(f"cannot write {what} {str(path)!r}: the file is read-only")
  try:  # The permission bits do not tell a read-only mount or /proc (nor anything to root).
    with tempfile.TemporaryFile(dir=ancestor):
      pass
  except OSError as error:
    raise ValueError(
      f"cannot write {what} {str(path)!r}: {str(ancestor)!r} takes no new file "
      f"({error.strerror or first_line(error)})"
    ) from None
  return path


_FILE_KINDS = (
  (stat.S_ISREG, "a file"),
  (stat.S_ISDIR, "a folder"),
  (stat.S_ISLNK, "a symbolic link"),
  (stat.S_ISFIFO, "a FIFO"),
  (stat.S_ISCHR, "a character device"),
  (stat.S_ISBLK, "a block device"),
  (stat.S_ISSOCK, "a socket"),
)


def file_kind(mode: int) -> str:
  """What a file of ``mode`` (an ``os.stat`` result's ``st_mode``) is, e.g. "a FIFO"."""
  return next((kind for test, kind in _FILE_KINDS if test(mode)), "a special file")


def check_regular_file(path: str | os.PathLike, what: str) -> None:
  """Refuses to read ``what`` (e.g. "trajectory file") from ``path`` unless it is a regular file
  (or a link to one): a FIFO would wait for a writer forever, a device never end.

  Raises:
    FileNotFoundError: nothing is there.
    ValueError: something other than a regular file is there (one line naming it).
  """
  mode = os.stat(path).st_mode
  if not stat.S_ISREG(mode):
    raise ValueError(f"{what} {path} is {file_kind(mode)}, not a regular file")


def check_home() -> pathlib.Path:
  """The data home, once it is known to take files; checked before any work that caches.

  Raises:
    ValueError: the data home is a file, lies under one, or cannot be written (one line).
  """
  return check_writable(softbench_home(), f"the data home ({_home_source()})", folder=True)


def _home_source() -> str:
  """Where the data home's path comes from, as a refusal names it (``softbench_home``)."""
  if os.environ.get(HOME_VARIABLE):
    return f"${HOME_VARIABLE}"
  if os.environ.get(CACHE_VARIABLE):
    return f"${CACHE_VARIABLE}/softbench"
  return "~/.cache/softbench"


def config_key(config, name: str) -> str:
  """A cache file's name for the frozen dataclass ``config`` (everything the cached thing depends
  on): ``name``, a dash and the first 12 hex digits of the sha256 of its fields' ``repr``."""
  text = repr(dataclasses.astuple(config)).encode()
  return f"{name}-{hashlib.sha256(text).hexdigest()[:12]}"


def arrays_sha256(arrays: dict[str, np.ndarray]) -> str:
  """A hash of named arrays' names, dtypes, shapes and bytes, independent of the file format."""
  digest = hashlib.sha256()
  for name in sorted(arrays):
    array = np.ascontiguousarray(arrays[name])
    digest.update(f"{name}|{array.dtype.str}|{array.shape}|".encode())
    digest.update(array.tobytes())
  return digest.hexdigest()


def npz_bytes(arrays: dict[str, np.ndarray]) -> bytes:
  """The bytes of an uncompressed ``.npz`` of ``arrays``; the same arrays give the same bytes."""
  buffer = io.BytesIO()
  np.savez(buffer, **{name: arrays[name] for name in sorted(arrays)})
  return buffer.getvalue()
