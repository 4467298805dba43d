"""Training an inverse model in closed loop through frozen forward models (``smpl.training``):
SMPL's progressive columns in order, the earlier ones frozen, or one centralised model; and the
forward models it trains through (``forward_models``), on the profile's babbling dataset."""

from typing import Callable

import torch

from smpl import fitting
from smpl import forward_model as smpl_forward
from smpl import progressive
from smpl import training
from smpl import windows as smpl_windows
from smpl.inverse import InverseModel
from softbench import data
from softbench import profiles
from softbench import progress as progress_bars
from softbench.learning import checkpoints
from softbench.learning import forward_models
from softbench.robots import base as robot_base

DATA_SEED = 0  # Every agent and seed learns from the same babbling dataset.
TRAINING_PARAMETERS = ("learning_rate", "batch_size", "weight_decay")  # The optimiser's settings.

ModelFactory = Callable[..., InverseModel]  # (input_size, action_size, **model settings) -> model
EpochCallback = Callable[[int, float], None]  # (epoch, counted across columns; validation loss)


def training_settings(params: dict) -> dict:
  """The entries of ``params`` that configure the optimiser."""
  return {name: value for name, value in params.items() if name in TRAINING_PARAMETERS}


def model_settings(params: dict) -> dict:
  """The entries of ``params`` that configure the model (keyword arguments of its factory)."""
  return {name: value for name, value in params.items() if name not in TRAINING_PARAMETERS}


def training_configs(
  seed: int, profile: profiles.Profile, params: dict | None = None
) -> tuple[training.ForwardTrainingConfig, training.InverseTrainingConfig]:
  """The forward model's config (the paper's, always) and the inverse model's (with ``params``'
  optimiser settings; ``hyperparameters.values``), seeded by ``seed``."""
  common = {**profile.training(), "seed": seed}
  del common["samples"]  # The dataset's size, not the optimiser's.
  return (
    training.ForwardTrainingConfig(**common),
    training.InverseTrainingConfig(**common, **training_settings(params or {})),
  )


def forward_config(seed: int, profile: profiles.Profile) -> training.ForwardTrainingConfig:
  """How the forward models of an agent trained with ``seed`` and ``profile`` are trained."""
  return training_configs(seed, profile)[0]


def _input_size(view: data.View) -> int:
  return smpl_windows.inverse_input_size(view.pose_size, view.action_size)


def _inverse_model(
  views: list[data.View], per_module: bool, make_model: ModelFactory, params: dict
) -> InverseModel:
  """An untrained inverse model for the views: a column per module (the paper's width and
  depth), or one centralised model configured by ``params``' model settings."""
  if per_module:
    inverse = progressive.ProgressiveLSTM()
    for view in views:
      inverse.add_column(_input_size(view), view.action_size)
    return inverse
  (view,) = views
  return make_model(_input_size(view), view.action_size, **model_settings(params))


def untrained(
  views: list[data.View], per_module: bool, make_model: ModelFactory | None, params: dict
) -> tuple[InverseModel, list[smpl_forward.ForwardModel]]:
  """Untrained inverse (configured by ``params``) and forward models for ``views``, to load a
  checkpoint into."""
  forwards = [
    smpl_forward.ForwardModel(view.preceding_action_size + view.action_size, view.pose_size)
    for view in views
  ]
  return _inverse_model(views, per_module, make_model, params), forwards


def trained_forward_models(
  robot: robot_base.SoftArm,
  views: list[data.View],
  seed: int,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> tuple[list[data.SplitWindows], list[smpl_forward.ForwardModel]]:
  """Each view's windows of the profile's babbling dataset (collected or found) and its frozen
  forward model, trained with ``forward_config(seed, profile)`` or found in the cache that every
  agent and tuning trial reading the same view shares (``forward_models``)."""
  dataset = data.collect(robot, samples=profile.samples, seed=DATA_SEED, progress=show_progress)
  return forward_models.prepare(
    robot,
    views,
    dataset,
    profile.samples,
    DATA_SEED,
    forward_config(seed, profile),
    checkpoints.TRAINING_VERSION,
    f"forward {robot.name} seed {seed}",
    show_progress,
  )


def train_inverse(
  views: list[data.View],
  windows: list[data.SplitWindows],
  forwards: list[smpl_forward.ForwardModel],
  seed: int,
  profile: profiles.Profile,
  per_module: bool,
  make_model: ModelFactory | None,
  params: dict,
  progress_label: str | None = None,
  show_progress: bool = False,
  on_epoch: EpochCallback | None = None,
  restart_diverged: bool = True,
) -> tuple[InverseModel, float]:
  """Trains a fresh inverse model with hyperparameters ``params`` in closed loop through the
  frozen forward models (one per view); returns it and its validation loss. A diverged training
  starts again with half the learning rate (``restart_diverged``; ``smpl.training``), which a
  tuning trial, scoring its own learning rate, turns off.

  The validation loss is the action MSE over the whole arm (normalised units, the aux term left
  out): a baseline's best validation loss, or for SMPL the columns' best losses weighted by their
  modules' action counts (a column's actions do not depend on the columns after it). Columns train
  in order, the earlier ones frozen. ``on_epoch`` gets every epoch (numbered ``column *
  profile.max_epochs + epoch``) and the validation loss so far: the trained columns' best losses
  and the training column's latest, weighted the same way.
  """
  _, inverse_config = training_configs(seed, profile, params)
  device = fitting.default_device()
  with fitting.seeded(seed, torch.device("cpu")):
    inverse = _inverse_model(views, per_module, make_model, params)
  action_sizes = [view.action_size for view in views]
  best_losses = []
  for index, view in enumerate(views):
    label = None if progress_label is None else f"inverse {progress_label} {view.name}"
    with progress_bars.epochs(label, profile.max_epochs, show_progress) as bar:
      epoch_end = _epoch_callback(
        bar,
        on_epoch,
        index * profile.max_epochs,
        lambda loss: _action_weighted(best_losses + [loss], action_sizes),
      )
      if per_module:  # Column by column, all acting together; the earlier ones stay frozen.
        inverse.columns.requires_grad_(False)
        inverse.columns[index].requires_grad_(True)
        result = training.train_column_jointly(
          inverse,
          forwards[: index + 1],
          smpl_windows.ModuleWindows(tuple(split.train for split in windows[: index + 1])),
          smpl_windows.ModuleWindows(tuple(split.validation for split in windows[: index + 1])),
          inverse_config,
          device,
          epoch_end,
          restart_diverged=restart_diverged,
        )
      else:
        result = training.train_inverse_model(
          inverse,
          forwards[index],
          windows[index].train,
          windows[index].validation,
          inverse_config,
          device,
          epoch_end,
          restart_diverged,
        )
    best_losses.append(result.best_validation_loss)
  inverse.requires_grad_(False)
  return inverse, _action_weighted(best_losses, action_sizes)


def _epoch_callback(
  bar, on_epoch: EpochCallback | None, first_epoch: int, loss_so_far: Callable[[float], float]
) -> Callable[[fitting.EpochReport], None]:
  """``smpl.fitting.fit``'s epoch callback: advances the progress bar, then calls ``on_epoch``."""

  def epoch_end(report: fitting.EpochReport) -> None:
    if bar is not None:
      bar(report)
    if on_epoch is not None:
      on_epoch(first_epoch + report.epoch, loss_so_far(report.validation_loss))

  return epoch_end


def _action_weighted(losses: list[float], action_sizes: list[int]) -> float:
  """Mean of per-view action MSEs weighted by action count: the MSE over all their actions."""
  sizes = action_sizes[: len(losses)]
  return sum(loss * size for loss, size in zip(losses, sizes)) / sum(sizes)
