"""Checkpoints of trained models: named by a hash of everything their weights depend on
(``TrainedConfig``), cached in the data home (or taken from the zoo), trained resumably when
missing (``load_or_train``)."""

import dataclasses
import pathlib
from typing import Callable

import numpy as np
import torch

from smpl import checkpoint
from smpl import forward_model as smpl_forward
from smpl import snapshots
from smpl.inverse import InverseModel
from softbench import data
from softbench import profiles
from softbench import storage
from softbench import zoo
from softbench.robots import base as robot_base

CHECKPOINT_FOLDER = "checkpoints"  # Under the data home.
SNAPSHOT_SUFFIX = ".partial"  # KEY.partial/ beside KEY.pt: an unfinished training's snapshots.
TRAINING_VERSION = 3  # Bump when training changes, so cached checkpoints are not reused. 2: SMPL
# columns train and act together, each on its own module's inputs. 3: validation (early stopping)
# leaves out the VAE's KL term; hyperparameters from hyperparameters.json.


@dataclasses.dataclass(frozen=True)
class TrainedConfig:
  """Everything a trained agent's weights depend on; its hash names the checkpoint."""

  agent: str
  robot: str
  robot_xml_sha256: str
  views: tuple[str, ...]
  samples: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  hyperparameters: tuple[tuple[str, float | int], ...] = ()  # Sorted (name, value) pairs.
  training_version: int = TRAINING_VERSION

  @property
  def key(self) -> str:
    return storage.config_key(self, f"{self.agent}-{self.robot}-seed{self.seed}")


def trained_config(
  name: str,
  robot: robot_base.SoftArm,
  views: list[data.View],
  seed: int,
  profile: profiles.Profile,
  params: dict,
) -> TrainedConfig:
  """The config that names the checkpoint of agent ``name`` trained with these settings."""
  return TrainedConfig(
    name,
    robot.name,
    robot.physics_sha256(),
    tuple(view.name for view in views),
    seed=seed,
    hyperparameters=tuple(sorted(params.items())),
    **profile.training(),
  )


def checkpoint_file(config: TrainedConfig) -> pathlib.Path:
  """The checkpoint named by ``config``."""
  return storage.softbench_home() / CHECKPOINT_FOLDER / f"{config.key}.pt"


@dataclasses.dataclass
class TrainedModels:
  """What a checkpoint holds: the inverse model, the forward models, the normalisation of each
  named part (a view, or a robot of a protocol) and any further named arrays."""

  inverse: InverseModel
  forwards: list[smpl_forward.ForwardModel]
  normalisations: list[data.Normalisation]
  arrays: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)


def bundle(inverse: InverseModel, forwards: list[smpl_forward.ForwardModel]) -> torch.nn.Module:
  """The module a checkpoint stores: the inverse model and every forward model."""
  return torch.nn.ModuleDict({"inverse": inverse, "forward_models": torch.nn.ModuleList(forwards)})


def load_or_train(
  path: pathlib.Path,
  config,
  parts: list[str],
  untrained_models: Callable[[], tuple[InverseModel, list[smpl_forward.ForwardModel]]],
  train: Callable[[], TrainedModels],
) -> TrainedModels:
  """The models of the checkpoint at ``path`` (saved for ``config``; taken from the zoo if the
  data home lacks it, ``softbench.zoo``), loaded into ``untrained_models()``. Otherwise, or if
  the file is damaged in any way (``storage.read_cached``: one ``CorruptFileWarning``),
  ``train()``'s, trained so that an interrupted training resumes
  (snapshots in ``snapshot_folder(path)``) and then saved there: normalisation i as
  ``parts[i]/KEY``, the further arrays under their own names (no part's prefix). Another process
  sharing the data home waits meanwhile (``storage.found_or_made``) and then loads it."""
  zoo.restore(path)

  def read(found: pathlib.Path) -> TrainedModels:
    inverse, forwards = untrained_models()
    stored = checkpoint.load_checkpoint(found, bundle(inverse, forwards), config)
    normalisations = [
      data.Normalisation.from_arrays(
        {
          key.removeprefix(f"{part}/"): value
          for key, value in stored.items()
          if key.startswith(f"{part}/")
        }
      )
      for part in parts
    ]
    arrays = {
      key: np.asarray(value) for key, value in stored.items() if key.split("/")[0] not in parts
    }
    return TrainedModels(inverse, forwards, normalisations, arrays)

  return storage.found_or_made(
    path,
    lambda: storage.read_cached(path, read, "checkpoint", "training it again"),
    lambda: _train_and_save(path, config, parts, train),
    "checkpoint",
  )


def _train_and_save(
  path: pathlib.Path, config, parts: list[str], train: Callable[[], TrainedModels]
) -> TrainedModels:
  """``train()``'s models, trained resumably and saved at ``path`` (``load_or_train``)."""
  with snapshots.resumable(snapshot_folder(path)):
    models = train()
  if set(key.split("/")[0] for key in models.arrays) & set(parts):
    raise ValueError(f"further arrays {sorted(models.arrays)} clash with the parts {parts}")
  scales = {
    f"{part}/{key}": value
    for part, scale in zip(parts, models.normalisations)
    for key, value in scale.to_arrays().items()
  }
  checkpoint.save_checkpoint(
    path, bundle(models.inverse, models.forwards), config, {**scales, **models.arrays}
  )
  snapshots.discard(snapshot_folder(path))
  return models


def snapshot_folder(checkpoint_path: pathlib.Path) -> pathlib.Path:
  """Where the training of a checkpoint keeps its snapshots until the checkpoint is written, so
  that an interrupted training resumes (``smpl.snapshots``)."""
  return checkpoint_path.with_suffix(SNAPSHOT_SUFFIX)
