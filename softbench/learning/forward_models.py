"""Frozen forward models, trained once and shared by every agent and tuning trial that needs them.

A forward model's weights depend on the robot, the view it predicts, the babbling dataset and its
training config (the paper's, seeded by the agent's seed), not on the inverse model trained through
it. So the agents that read the same view with the same seed and profile (the four baselines'
whole-arm model) and every trial of a tuning study share one: trained as
``softbench.learning.protocols.prepare_column`` trains it, cached under ``$SOFTBENCH_HOME/forward``
by a hash of everything its weights depend on (``ForwardModelConfig``), or taken from the zoo
(``softbench.zoo``), and loaded with the weights a fresh training gives, to the bit. An interrupted
training resumes from its snapshots (``smpl.snapshots``, in the cache file's ``.partial`` folder); a
damaged cache file is reported and trained again (``storage.read_cached``).
"""

import dataclasses
import pathlib

from smpl import checkpoint
from smpl import fitting
from smpl import forward_model as smpl_forward
from smpl import snapshots
from smpl import training
from softbench import data
from softbench import progress as progress_bars
from softbench import storage
from softbench import zoo
from softbench.learning import checkpoints
from softbench.learning import protocols
from softbench.robots import base as robot_base

FOLDER = "forward"  # Under the data home.


@dataclasses.dataclass(frozen=True)
class ForwardModelConfig:
  """Everything a cached forward model's weights depend on; its hash names the file."""

  robot: str
  robot_xml_sha256: str
  view: str
  samples: int
  data_seed: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  training_version: int

  @property
  def key(self) -> str:
    return storage.config_key(self, f"{self.robot}-{self.view}-seed{self.seed}")


def cache_file(config: ForwardModelConfig) -> pathlib.Path:
  """Where the forward model of ``config`` is cached (it exists once trained)."""
  return storage.softbench_home() / FOLDER / f"{config.key}.pt"


def configs(
  robot: robot_base.SoftArm,
  views: list[data.View],
  samples: int,
  data_seed: int,
  config: training.ForwardTrainingConfig,
  training_version: int,
) -> list[ForwardModelConfig]:
  """The cache configs of ``views``' forward models trained with ``config`` (``prepare``)."""
  xml_sha256 = robot.physics_sha256()
  return [
    ForwardModelConfig(
      robot.name,
      xml_sha256,
      view.name,
      samples,
      data_seed,
      config.seed,
      config.max_epochs,
      config.patience,
      config.compile,
      training_version,
    )
    for view in views
  ]


def prepare(
  robot: robot_base.SoftArm,
  views: list[data.View],
  dataset: data.Dataset,
  samples: int,
  data_seed: int,
  config: training.ForwardTrainingConfig,
  training_version: int,
  progress_label: str | None = None,
  show_progress: bool = False,
) -> tuple[list[data.SplitWindows], list[smpl_forward.ForwardModel]]:
  """Each view's windows of ``dataset`` (``samples`` babbling samples of seed ``data_seed``) and
  its frozen forward model trained with ``config``: from the cache, or trained now (with an epoch
  progress bar named ``progress_label VIEW`` if given) and cached; another process sharing the
  data home waits meanwhile (``storage.found_or_made``) and then loads it."""
  windows, forwards = [], []
  for view, key in zip(views, configs(robot, views, samples, data_seed, config, training_version)):
    path = cache_file(key)
    partial = checkpoints.snapshot_folder(path)  # Its training snapshots until it is saved.
    zoo.restore(path)

    def train() -> tuple[data.SplitWindows, smpl_forward.ForwardModel]:
      with (
        snapshots.resumable(partial),
        progress_bars.epochs(
          None if progress_label is None else f"{progress_label} {view.name}",
          config.max_epochs,
          show_progress,
        ) as bar,
      ):
        column = protocols.prepare_column(
          robot, view, dataset, config, fitting.default_device(), bar
        )
      checkpoint.save_checkpoint(path, column.forward_model, key)
      snapshots.discard(partial)
      return column.windows, column.forward_model

    split, model = storage.found_or_made(
      path, lambda: _cached(path, key, dataset, view), train, "forward model"
    )
    windows.append(split)
    forwards.append(model.eval())
  return windows, forwards


def _cached(
  path: pathlib.Path, key: ForwardModelConfig, dataset: data.Dataset, view: data.View
) -> tuple[data.SplitWindows, smpl_forward.ForwardModel] | None:
  """``_load`` of the cached file, None if there is none (or it is damaged: reported once)."""
  return storage.read_cached(
    path, lambda found: _load(found, key, dataset, view), "forward model", "training it again"
  )


def _load(
  path: pathlib.Path, key: ForwardModelConfig, dataset: data.Dataset, view: data.View
) -> tuple[data.SplitWindows, smpl_forward.ForwardModel]:
  """The view's windows and the frozen forward model cached at ``path``; raises if the file
  fails its checks."""
  split = data.windows(dataset, view)
  model = smpl_forward.ForwardModel(split.train.actuation_size, split.train.pose_size)
  checkpoint.load_checkpoint(path, model, key)
  return split, model.freeze()
