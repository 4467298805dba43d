"""Motor-babbling data: collection, cached datasets, splits, normalisation and windows.

Time convention throughout: action a_s is held for one control period while the arm is at pose
x_s and brings it to x_{s+1}; x_0 is the rest pose, so pose index s comes before action s (as in
``smpl.windows``).

  collect(robot, samples, seed, workers)  record (or resume, or find) a dataset   [babbling]
  load(robot, samples, seed)              a verified dataset, collected before     [dataset]
  windows(dataset, View.module(robot, k)) normalised train/validation/test windows [views]
  rng(seed, stream, *index)               softbench's independent random streams  [seeding]

Each name is loaded from its module on first use (``lazy_loader``): the collection loads MuJoCo,
the windows torch, and the seed streams neither, so the registries import them without an engine.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
  __name__,
  submodules=["babbling", "chunks", "dataset", "normalisation", "seeding", "splits", "views"],
  submod_attrs={
    "babbling": ["CHUNK_LENGTH", "babbling_actions", "collect"],
    "dataset": [
      "DEFAULT_SAMPLES",
      "EPISODE_LENGTH",
      "Dataset",
      "DatasetError",
      "dataset_folder",
      "episode_lengths",
      "generating_config",
      "load",
      "read",
    ],
    "normalisation": ["MinMaxNormaliser", "Normalisation"],
    "seeding": ["BABBLING_STREAM", "HELD_OUT_BABBLING_STREAM", "rng"],
    "splits": ["FRACTIONS", "SPLITS", "Piece", "split_pieces"],
    "views": ["SplitWindows", "View", "windows"],
  },
)
