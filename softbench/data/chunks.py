"""The chunks a babbling collection saves as it goes, so that a stopped collection resumes.

Chunk files live in ``<dataset folder>/partial/``, one per stretch ``[start, stop)`` of control
steps, named ``chunk-{start:06d}-{stop:06d}.npz``. Each holds, for every episode, the poses after
each of those steps (``poses``, (episodes, stop - start, num_modules, 6)), the full physics states
after the last one (``final_states``, from which ``PoseRecorder`` continues bit for bit), the step
range (``steps``), the key of the collection it belongs to (``collection``: a chunk copied from
another collection is refused) and the sha256 of all four (``sha256``, by
``storage.arrays_sha256``). Files
are written atomically. A chunk is used only if it reads back whole, fits the collection and
matches its hash; otherwise it is reported (``CorruptFileWarning``, ``storage.read_cached``),
deleted and computed again.
"""

import dataclasses
import pathlib

import numpy as np

from softbench import storage
from softbench.data import dataset
from softbench.robots import recorder

PARTIAL_FOLDER = "partial"


class ChunkError(ValueError):
  """A chunk file is unreadable, corrupt, or does not fit the collection."""


@dataclasses.dataclass(frozen=True, eq=False)
class Chunk:
  """Control steps ``[start, stop)`` of every episode; arrays as in the module docstring."""

  start: int
  stop: int
  poses: np.ndarray
  final_states: np.ndarray

  def arrays(self) -> dict[str, np.ndarray]:
    return {
      "steps": np.array([self.start, self.stop], dtype="<i8"),
      "poses": np.asarray(self.poses, dtype="<f8"),
      "final_states": np.asarray(self.final_states, dtype="<f8"),
    }


@dataclasses.dataclass(frozen=True)
class Layout:
  """What every chunk of one collection must fit, and which collection it belongs to."""

  episodes: int
  steps: int  # Control steps of the longest episode.
  num_modules: int
  state_size: int
  collection: str = ""  # The dataset's key (``dataset.dataset_key``): robot, samples, seed, ...


def chunk_path(folder: pathlib.Path, start: int, stop: int) -> pathlib.Path:
  return folder / f"chunk-{start:06d}-{stop:06d}.npz"


def write(folder: pathlib.Path, chunk: Chunk, collection: str) -> None:
  """Saves ``chunk`` of the collection keyed ``collection`` (``Layout.collection``)."""
  arrays = {**chunk.arrays(), "collection": np.array(collection)}
  arrays["sha256"] = np.array(storage.arrays_sha256(arrays))
  storage.write_cache_file(
    chunk_path(folder, chunk.start, chunk.stop), storage.npz_bytes(arrays), "babbling chunk"
  )


def read(path: pathlib.Path, layout: Layout) -> Chunk:
  """The chunk in ``path``; raises ChunkError (one line) if it fails a check."""
  arrays = dataset.read_npz(path.read_bytes(), ChunkError)
  if sorted(arrays) != ["collection", "final_states", "poses", "sha256", "steps"]:
    raise ChunkError(f"holds arrays {sorted(arrays)}")
  stored_hash = arrays.pop("sha256")
  if stored_hash.shape != () or str(stored_hash) != storage.arrays_sha256(arrays):
    raise ChunkError("sha256 mismatch (corrupt file)")
  if str(arrays.pop("collection")) != layout.collection:
    raise ChunkError(f"a chunk of another collection, not of {layout.collection}")
  start, stop = (int(step) for step in arrays["steps"])
  if (
    f"-{start:06d}-{stop:06d}." not in path.name
    or not 0 <= start < stop <= layout.steps
    or arrays["poses"].shape
    != (layout.episodes, stop - start, layout.num_modules, recorder.POSE_SIZE)
    or arrays["final_states"].shape != (layout.episodes, layout.state_size)
  ):
    raise ChunkError("does not fit this collection (steps or shapes differ)")
  return Chunk(start, stop, arrays["poses"], arrays["final_states"])


def resume(folder: pathlib.Path, layout: Layout) -> list[Chunk]:
  """The chain of valid chunks from step 0, as far as it goes; bad chunks on the way are
  reported with a ``CorruptFileWarning`` and deleted (``storage.read_cached``)."""
  chain = []
  step = 0
  while step < layout.steps:
    candidates = sorted(
      folder.glob(f"chunk-{step:06d}-*.npz"), key=lambda path: path.name, reverse=True
    )  # The longest first.
    chunk = None
    for path in candidates:
      chunk = storage.read_cached(
        path, lambda found: read(found, layout), "babbling chunk", "computing it again"
      )
      if chunk is not None:
        break
    if chunk is None:
      break
    chain.append(chunk)
    step = chunk.stop
  return chain
