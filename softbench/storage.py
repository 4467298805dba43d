"""Where softbench keeps its files, and how it writes them: atomically, with content hashes.

The data home is ``$SOFTBENCH_HOME`` if set, else ``$XDG_CACHE_HOME/softbench`` (by default
``~/.cache/softbench``). Every file goes through a temporary file in the same folder and an
``os.replace``, so a reader sees the old file or the new one, never half of one.
"""

import hashlib
import io
import os
import pathlib
import tempfile

import numpy as np

HOME_VARIABLE = "SOFTBENCH_HOME"


def softbench_home() -> pathlib.Path:
  """The folder under which datasets, reference trajectories and checkpoints are cached."""
  if os.environ.get(HOME_VARIABLE):
    return pathlib.Path(os.environ[HOME_VARIABLE]).expanduser()
  cache = os.environ.get("XDG_CACHE_HOME") or pathlib.Path.home() / ".cache"
  return pathlib.Path(cache) / "softbench"


_FILE_MODE = 0o666  # What open() requests for a new file.


def write_atomically(path: pathlib.Path, content: str | bytes) -> None:
  """Writes ``content`` (text or bytes) to ``path`` through a temporary file and a rename.

  The file gets the permissions a plain ``open`` would give (0666 less the umask), not the
  owner-only mode of the temporary file. A failed write (a full disk, ``path`` a folder) removes
  the temporary file and raises its error."""
  path = pathlib.Path(path)
  path.parent.mkdir(parents=True, exist_ok=True)
  handle, temporary = tempfile.mkstemp(suffix=".tmp", dir=path.parent)
  try:
    with os.fdopen(handle, "wb" if isinstance(content, bytes) else "w") as file:
      file.write(content)
      file.flush()
      os.fsync(file.fileno())
    os.chmod(temporary, _FILE_MODE & ~_umask())
    os.replace(temporary, path)
  except BaseException:
    pathlib.Path(temporary).unlink(missing_ok=True)
    raise


def check_writable(path: str | os.PathLike, what: str, folder: bool = False) -> pathlib.Path:
  """``path`` as a ``Path`` if ``what`` (e.g. "video") can be written there: a file (or, with
  ``folder``, a folder of files) whose missing parent folders can be made. Checked before long
  work, so that it does not end in a failed write.

  Raises:
    ValueError: ``path`` is a folder where a file is wanted or the other way round, a parent is
      a file, or there is no permission to write (one line).
  """
  path = pathlib.Path(path)
  if path.exists() and path.is_dir() != folder:
    raise ValueError(f"cannot write {what} {str(path)!r}: it is "
                     f"{'a file' if folder else 'a folder'}")
  ancestor = path.absolute() if folder else path.absolute().parent
  while not ancestor.exists():
    ancestor = ancestor.parent
  if not ancestor.is_dir():
    raise ValueError(f"cannot write {what} {str(path)!r}: {str(ancestor)!r} is not a folder")
  if not os.access(ancestor, os.W_OK | os.X_OK):
    raise ValueError(f"cannot write {what} {str(path)!r}: no permission to write in "
                     f"{str(ancestor)!r}")
  if not folder and path.exists() and not os.access(path, os.W_OK):
    raise ValueError(f"cannot write {what} {str(path)!r}: the file is read-only")
  return path


def _umask() -> int:
  current = os.umask(0)
  os.umask(current)
  return current


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
