"""Motor-babbling data: collection, cached datasets, splits, normalisation and windows.

Time convention throughout: action a_s is held for one control period while the arm is at pose
x_s and brings it to x_{s+1}; x_0 is the rest pose, so pose index s comes before action s (as in
``smpl.windows``).

  collect(robot, samples, seed, workers)  record (or resume, or find) a dataset   [babbling]
  load(robot, samples, seed)              a verified dataset, collected before     [dataset]
  windows(dataset, View.module(robot, k)) normalised train/validation/test windows [views]
  rng(seed, stream, *index)               softbench's independent random streams  [seeding]
"""

from softbench.data.babbling import CHUNK_LENGTH
from softbench.data.babbling import babbling_actions
from softbench.data.babbling import collect
from softbench.data.dataset import DEFAULT_SAMPLES
from softbench.data.dataset import EPISODE_LENGTH
from softbench.data.dataset import Dataset
from softbench.data.dataset import DatasetError
from softbench.data.dataset import dataset_folder
from softbench.data.dataset import episode_lengths
from softbench.data.dataset import generating_config
from softbench.data.dataset import load
from softbench.data.dataset import read
from softbench.data.normalisation import MinMaxNormaliser
from softbench.data.normalisation import Normalisation
from softbench.data.seeding import BABBLING_STREAM
from softbench.data.seeding import HELD_OUT_BABBLING_STREAM
from softbench.data.seeding import rng
from softbench.data.splits import FRACTIONS
from softbench.data.splits import SPLITS
from softbench.data.splits import Piece
from softbench.data.splits import split_pieces

_VIEWS = ("SplitWindows", "View", "windows")  # In data.views, which needs torch: loaded on use,
# so that the physics side (robots, suite, rendering) imports without torch.


def __getattr__(name: str):
  if name in _VIEWS:
    from softbench.data import views  # pylint: disable=import-outside-toplevel

    return getattr(views, name)
  raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
  "BABBLING_STREAM",
  "CHUNK_LENGTH",
  "DEFAULT_SAMPLES",
  "EPISODE_LENGTH",
  "FRACTIONS",
  "HELD_OUT_BABBLING_STREAM",
  "SPLITS",
  "Dataset",
  "DatasetError",
  "MinMaxNormaliser",
  "Normalisation",
  "Piece",
  "SplitWindows",
  "View",
  "babbling_actions",
  "collect",
  "dataset_folder",
  "episode_lengths",
  "generating_config",
  "load",
  "read",
  "rng",
  "split_pieces",
  "windows",
]
