"""Training smpl's models through one loop (`smpl.fitting.fit`): the losses and their settings.

`train_forward_model` and `train_inverse_model` supply the loss to `fitting.fit`: teacher-forced
next-pose MSE for the forward model, and for inverse models the action MSE of a closed-loop (or
open-loop) rollout through the frozen forward model (see `smpl.rollout` for the exact time
indexing).

Inverse-model loss: MSE between predicted and babbling actions (supervised, as in the paper), plus
the model's aux loss (the VAE's beta * KL), plus optionally `pose_loss_weight` times the MSE between
the forward model's predicted poses and the targets (off by default). The aux loss is a training
regulariser only: validation, and so early stopping and the best weights kept, leaves it out, which
makes every inverse model's validation loss the same quantity.

Divergence: given `restart_diverged`, an inverse-model training has diverged when its best
validation loss is no lower than that of always acting zero (the middle of the normalised action
range) and an epoch's training loss rose to `DIVERGED_LOSS_FACTOR` times that (a short training
that has not learned yet is not diverged); it starts again from its initial weights with half
the learning rate, at most `DIVERGENCE_RESTARTS` times, with a warning each time. A training that
did not diverge is untouched, to the bit.
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Sequence
import dataclasses
from dataclasses import dataclass
import warnings

import torch
from torch import Tensor
from torch import nn

from smpl import fitting
from smpl.forward_model import ForwardModel
from smpl.inverse import InverseModel
from smpl.progressive import ProgressiveLSTM
from smpl.rollout import joint_rollout
from smpl.rollout import rollout
from smpl.windows import BabblingWindows
from smpl.windows import ModuleWindows

FORWARD_BATCH_SIZE = 64
"""Windows per forward-model batch (paper)."""
INVERSE_BATCH_SIZE = 32
"""Windows per inverse-model batch (paper, SMPL)."""
DIVERGENCE_RESTARTS = 3
"""Restarts of a diverged inverse-model training, each with half the previous learning rate. The
MLP's tuned rate (8.3e-3) diverged on 3 of 5 seeds of pneumatic-433's 14,000 samples (gradient
norms up to 2.5e5 in the first epoch). The rule sees only the weights kept: a training that
diverges after a good enough epoch keeps that epoch."""
DIVERGED_LOSS_FACTOR = 10.0
"""How far above acting zero's loss an epoch's training loss must rise for a training that ends no
better than acting zero to count as diverged. The MLP's diverged trainings reached 35 to 175
times; undertrained ones (2 epochs of the tests' tiny profile) stay near 1."""


@dataclass(frozen=True)
class ForwardTrainingConfig(fitting.TrainingConfig):
  batch_size: int = FORWARD_BATCH_SIZE


@dataclass(frozen=True)
class InverseTrainingConfig(fitting.TrainingConfig):
  batch_size: int = INVERSE_BATCH_SIZE
  feed_back_error: bool = True
  """Closed loop (the error input comes from the forward model) or open loop (it stays zero)."""
  pose_loss_weight: float = 0.0
  """Weight of the forward-model pose MSE added to the action MSE; 0 trains on actions only."""


def forward_model_loss(forward_model: ForwardModel, windows: BabblingWindows) -> Tensor:
  """Next-pose MSE with the recorded poses and actuation as inputs (teacher forcing)."""
  predicted = forward_model(
    windows.previous_poses, windows.current_poses, windows.actuation(windows.actions)
  )
  return nn.functional.mse_loss(predicted, windows.next_poses)


def inverse_model_loss(
  inverse_model: InverseModel,
  forward_model: ForwardModel,
  windows: BabblingWindows,
  feed_back_error: bool = True,
  pose_loss_weight: float = 0.0,
  include_aux_loss: bool = True,
) -> Tensor:
  """Action MSE of a rollout, plus aux loss (unless `include_aux_loss` is false), plus the
  optional pose term (module docstring)."""
  needs_forward_model = feed_back_error or pose_loss_weight > 0
  result = rollout(
    inverse_model, windows, forward_model if needs_forward_model else None, feed_back_error
  )
  loss = nn.functional.mse_loss(result.actions, windows.actions)
  if include_aux_loss:
    loss = loss + result.aux_loss
  if pose_loss_weight > 0:
    loss = loss + pose_loss_weight * nn.functional.mse_loss(
      result.predicted_poses, windows.next_poses
    )
  return loss


def train_forward_model(
  forward_model: ForwardModel,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: fitting.TrainingConfig = ForwardTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[fitting.EpochReport], None] | None = None,
) -> fitting.TrainingResult:
  """Trains the forward model on babbling windows, then freezes it."""
  result = fitting.fit(
    forward_model,
    lambda windows: forward_model_loss(forward_model, windows),
    train,
    validation,
    config,
    device,
    on_epoch_end,
  )
  forward_model.freeze()
  return result


def train_inverse_model(
  inverse_model: InverseModel,
  forward_model: ForwardModel,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[fitting.EpochReport], None] | None = None,
  restart_diverged: bool = False,
) -> fitting.TrainingResult:
  """Trains an inverse model (any of them, including the last SMPL column) through the loop;
  validation leaves out the model's aux loss; `restart_diverged`: see the module docstring."""
  if not forward_model.is_frozen:
    raise ValueError("the forward model must be trained and frozen before the inverse model")
  device = device if device is not None else fitting.default_device()
  forward_model.eval()

  def loss(windows: BabblingWindows, include_aux_loss: bool = True) -> Tensor:
    return inverse_model_loss(
      inverse_model,
      forward_model,
      windows,
      config.feed_back_error,
      config.pose_loss_weight,
      include_aux_loss,
    )

  with fitting.on_device(device, forward_model):
    return _fit_restarting(
      inverse_model,
      loss,
      train,
      validation,
      config,
      device,
      on_epoch_end,
      lambda windows: loss(windows, include_aux_loss=False),
      _zero_action_loss([validation.actions]) if restart_diverged else None,
    )


def train_column_jointly(
  network: ProgressiveLSTM,
  forward_models: Sequence[ForwardModel],
  train: ModuleWindows,
  validation: ModuleWindows,
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[fitting.EpochReport], None] | None = None,
  column: int | None = None,
  restart_diverged: bool = False,
) -> fitting.TrainingResult:
  """Trains one of columns 0..M-1 (M = modules in `train`) of a distributed controller, all
  columns acting together on their own modules (`smpl.rollout.joint_rollout`).

  By default the column is the last, M-1, and the loss is the action MSE of its module; every
  earlier column must be trained and frozen. Given an earlier `column` (retraining it, e.g.
  after an actuator fault), the loss is the mean action MSE of modules `column`..M-1, every
  module whose column reads it through the lateral connections, and every other column must
  be frozen. `restart_diverged`: see the module docstring.
  """
  last = len(train.modules) - 1
  if column is not None and not 0 <= column <= last:
    raise ValueError(f"column must be 0 to {last} for {last + 1} modules, got {column}")
  column = last if column is None else column
  others = [network.columns[index] for index in range(len(network.columns)) if index != column]
  if any(parameter.requires_grad for other in others for parameter in other.parameters()):
    raise ValueError(
      "the earlier columns must be frozen before the next one trains"
      if column == last
      else f"every column but {column} must be frozen to retrain it"
    )
  if not all(model.is_frozen for model in forward_models):
    raise ValueError("the forward models must be trained and frozen before the inverse model")
  device = device if device is not None else fitting.default_device()
  for model in forward_models:
    model.eval()

  loss = joint_action_loss(network, forward_models, column, config.feed_back_error)
  zero_action_loss = (
    _zero_action_loss([w.actions for w in validation.modules[column:]])
    if restart_diverged
    else None
  )
  with fitting.on_device(device, *forward_models):
    return _fit_restarting(
      network, loss, train, validation, config, device, on_epoch_end, None, zero_action_loss
    )


def joint_action_loss(
  network: ProgressiveLSTM,
  forward_models: Sequence[ForwardModel],
  first: int = 0,
  feed_back_error: bool = True,
  acted_preceding: bool = False,
) -> fitting.BatchLoss:
  """The batch loss of columns acting together (`smpl.rollout.joint_rollout`): the mean over
  modules `first`..M-1 of each module's action MSE."""

  def loss(windows: ModuleWindows) -> Tensor:
    results = joint_rollout(network, windows, forward_models, feed_back_error, acted_preceding)
    losses = [
      nn.functional.mse_loss(results[index].actions, windows.modules[index].actions)
      for index in range(first, len(windows.modules))
    ]
    return sum(losses[1:], losses[0]) / len(losses)

  return loss


def _zero_action_loss(actions: Sequence[Tensor]) -> float:
  """The validation loss of always acting zero: the mean over modules of each one's mean
  squared normalised action."""
  return sum(float(torch.mean(module**2)) for module in actions) / len(actions)


def _diverged(result: fitting.TrainingResult, zero_action_loss: float) -> bool:
  """Whether a training diverged (module docstring)."""
  return (
    result.best_validation_loss >= zero_action_loss
    and max(report.train_loss for report in result.history)
    >= DIVERGED_LOSS_FACTOR * zero_action_loss
  )


def _fit_restarting(
  model: nn.Module,
  batch_loss: fitting.BatchLoss,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: fitting.TrainingConfig,
  device: torch.device | None,
  on_epoch_end: Callable[[fitting.EpochReport], None] | None,
  validation_loss: fitting.BatchLoss | None,
  zero_action_loss: float | None,
) -> fitting.TrainingResult:
  """`fitting.fit`; when `zero_action_loss` is given, a diverged fit (`_diverged`) starts again
  from the initial weights with half the learning rate (module docstring)."""
  initial = fitting.copy_state(model) if zero_action_loss is not None else None
  for restart in range(DIVERGENCE_RESTARTS + 1):
    result = fitting.fit(
      model, batch_loss, train, validation, config, device, on_epoch_end, validation_loss
    )
    if zero_action_loss is None or not _diverged(result, zero_action_loss):
      break
    if restart == DIVERGENCE_RESTARTS:
      warnings.warn(
        f"training of seed {config.seed} still diverged after {restart} "
        f"restarts (best validation loss {result.best_validation_loss:.3g}, "
        f"acting zero {zero_action_loss:.3g}, learning rate "
        f"{config.learning_rate:.3g})"
      )
      break
    warnings.warn(
      f"training of seed {config.seed} diverged (best validation loss "
      f"{result.best_validation_loss:.3g}, no lower than {zero_action_loss:.3g} "
      f"for acting zero); training again from the initial weights with "
      f"learning rate {config.learning_rate / 2:.3g}"
    )
    model.load_state_dict(initial)
    config = dataclasses.replace(config, learning_rate=config.learning_rate / 2)
  if restart:
    result.restarts, result.learning_rate = restart, config.learning_rate
  return result
