"""Exp1S's network: one progressive network trained column by column on the arms of a tendon
family (1 module, then 2, ...), the earlier columns frozen (``protocols``), cached as a checkpoint
named by everything it depends on (``Exp1sConfig``) with its model-level forgetting matrices."""

import dataclasses
import pathlib

import numpy as np

from smpl import fitting
from smpl import protocol as smpl_protocol
from softbench import profiles
from softbench import progress as progress_bars
from softbench import robots
from softbench import storage
from softbench.data import View
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training
from softbench.learning import protocols
from softbench.records.exp1s import DEFAULT_FAMILY
from softbench.records.exp1s import PROTOCOL


def protocol(family: str = DEFAULT_FAMILY) -> protocols.Protocol:
  """Exp1S on the arms of tendon family ``family``; raises a one-line ValueError for an unknown
  family."""
  if family not in robots.TENDON_FAMILY_NAMES:
    raise ValueError(
      f"unknown tendon family {family!r}; choose one of {', '.join(robots.TENDON_FAMILY_NAMES)}"
    )
  return protocols.get(PROTOCOL).on_family(family)


@dataclasses.dataclass(frozen=True)
class Exp1sConfig:
  """Everything the sequentially trained network depends on; its hash names the checkpoint."""

  robots: tuple[str, ...]
  robot_xml_sha256: tuple[str, ...]
  samples: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  # SMPL's hyperparameters (softbench.agents.hyperparameters).
  params: tuple[tuple[str, object], ...]
  training_version: int = checkpoints.TRAINING_VERSION

  @property
  def key(self) -> str:
    return storage.config_key(self, f"{PROTOCOL}-seed{self.seed}")


def config(seed: int, profile: profiles.Profile, arms: list, params: dict) -> Exp1sConfig:
  """The config that names the checkpoint of ``seed``'s network on ``arms``."""
  return Exp1sConfig(
    tuple(arm.name for arm in arms),
    tuple(arm.physics_sha256() for arm in arms),
    seed=seed,
    params=tuple(sorted(params.items())),
    **profile.training(),
  )


def _train(
  seed: int, profile: profiles.Profile, params: dict, show: bool, family: str
) -> checkpoints.TrainedModels:
  """Column by column over the configurations; the forgetting matrices as further arrays."""
  sequence = protocol(family)
  forward_config, inverse_config = inverse_training.training_configs(seed, profile, params)
  epoch_bars = lambda label: progress_bars.epochs(
    f"{label} ({PROTOCOL} seed {seed})", profile.max_epochs, show
  )
  result = protocols.run(
    sequence,
    profile.samples,
    inverse_training.DATA_SEED,
    forward_config,
    inverse_config,
    fitting.default_device(),
    show,
    epoch_bars,
  )
  result.network.requires_grad_(False)
  return checkpoints.TrainedModels(
    result.network,
    [column.forward_model for column in result.columns],
    [column.windows.normalisation for column in result.columns],
    _matrices(result.run),
  )


def _matrices(outcome: smpl_protocol.ProgressiveRun) -> dict[str, np.ndarray]:
  return {
    f"forgetting/{metric}": outcome.forgetting_matrix(metric).numpy()
    for metric in ("pose_mse", "action_mse")
  }


def checkpoint_path(
  seed: int, profile: profiles.Profile, params: dict, family: str = DEFAULT_FAMILY
) -> pathlib.Path:
  """Where ``load_or_train`` caches the Exp1S network of ``seed`` (it exists once trained)."""
  arms = [arm for arm, _ in protocol(family).column_views()]
  return checkpoints.checkpoint_file(config(seed, profile, arms, params))


def load_or_train(
  seed: int,
  profile: profiles.Profile,
  params: dict,
  show_progress: bool = False,
  family: str = DEFAULT_FAMILY,
) -> tuple[checkpoints.TrainedModels, list, list[View]]:
  """The Exp1S network of ``seed`` trained with SMPL's ``params`` (in eval mode), from the
  checkpoint cache or trained now and cached; with the arms and the views of its columns."""
  views_of = protocol(family).column_views()
  arms = [arm for arm, _ in views_of]
  views = [view for _, view in views_of]
  named = config(seed, profile, arms, params)
  models = checkpoints.load_or_train(
    checkpoints.checkpoint_file(named),
    named,
    [arm.name for arm in arms],
    lambda: inverse_training.untrained(views, True, None, params),
    lambda: _train(seed, profile, params, show_progress, family),
  )
  models.inverse.eval()
  return models, arms, views
