"""What every continual strategy is: a learner that meets a stream's configurations one stage at a
time, and after every stage can drive each configuration it has seen.

A strategy keeps everything it carries from one stage to the next in ``self.module`` (weights,
and any buffers: EWC's Fisher information, a replay buffer's windows), so that the state after a
stage is one ``state_dict``, cached and reloaded by ``softbench.continual.training``. Before
stage s it ``grow``s (SMPL adds a column, ``independent`` a network), then ``learn``s from the
stages' data; ``controller(c)`` is configuration c's inverse model now.

All strategies train with one ``smpl.training.InverseTrainingConfig`` per stage (the profile's
epoch budget and patience, SMPL's committed optimiser settings, the run's seed), in closed loop
through each configuration's frozen forward model; validation and early stopping read the
stage's own validation windows (action MSE), never a regulariser.
"""

import abc
import dataclasses
import hashlib
from typing import ClassVar

import torch
from torch import nn

from smpl import fitting
from smpl import forward_model as smpl_forward
from smpl import training
from smpl.inverse import InverseModel
from softbench import data
from softbench.continual import streams


@dataclasses.dataclass(frozen=True, eq=False)
class StageData:
  """One stage's configuration, its windows (splits and normalisation) and frozen forward
  model."""

  configuration: streams.Configuration
  windows: data.SplitWindows
  forward: smpl_forward.ForwardModel

  @property
  def action_size(self) -> int:
    return self.windows.train.action_size

  @property
  def pose_size(self) -> int:
    return self.windows.train.pose_size


@dataclasses.dataclass(frozen=True)
class Setting:
  """What a strategy knows of its run before the first stage: the stream's sizes (every
  configuration's action count, the shared pose size), the training config and device."""

  pose_size: int
  action_sizes: tuple[int, ...]
  config: training.InverseTrainingConfig
  device: torch.device

  @property
  def seed(self) -> int:
    return self.config.seed


@dataclasses.dataclass(frozen=True)
class StageTraining:
  """What one stage's training did: the fits it ran (none for a strategy that learned everything
  earlier) and the configurations whose data it read."""

  results: tuple[fitting.TrainingResult, ...]
  trained_on: tuple[int, ...]


class Strategy(abc.ABC):
  """A continual strategy (module docstring)."""

  continual: ClassVar[bool] = True
  """False for a strategy that is not continual (``joint``): it gets every stage's data at the
  first stage; a continual one gets stages 0..s at stage s."""

  def __init__(self, setting: Setting) -> None:
    self.setting = setting
    self.module = nn.Module()

  @classmethod
  def constants(cls) -> dict:
    """The strategy's own settings that its weights depend on (EWC's lambda, a buffer's size),
    by name: they enter the cache key of its stages."""
    return {}

  @classmethod
  def check(cls, configurations: tuple[streams.Configuration, ...]) -> None:
    """Raises a one-line ValueError if this strategy cannot run a stream of ``configurations``
    (every registered strategy runs every registered stream)."""

  def grow(self, stage: int) -> None:
    """Makes room for stage ``stage`` before it learns (and before a cached state is loaded)."""

  @abc.abstractmethod
  def learn(self, stage: int, stages: list[StageData], on_epoch_end) -> StageTraining:
    """Learns stage ``stage`` from ``stages`` (0..stage, or every stage for a strategy that is
    not ``continual``); ``on_epoch_end`` gets each epoch's ``smpl.fitting.EpochReport``."""

  @abc.abstractmethod
  def controller(self, configuration: int) -> InverseModel:
    """The inverse model that drives configuration ``configuration`` now, in eval mode."""

  def controller_digest(self, configuration: int) -> str:
    """A hash of every weight the controller of ``configuration`` reads: equal digests act
    alike, to the bit, so an episode is not run twice for them."""
    return tensors_digest(self.controller(configuration).state_dict())

  def new_seeded(self, offset: int, build):
    """``build()`` with torch seeded by the run's seed plus ``offset`` (a new network's initial
    weights)."""
    with fitting.seeded(self.setting.seed + offset, torch.device("cpu")):
      return build()


def fit_configuration(
  model: InverseModel,
  stage: StageData,
  setting: Setting,
  on_epoch_end,
  penalty=None,
  forwards: tuple[smpl_forward.ForwardModel, ...] = (),
) -> fitting.TrainingResult:
  """Trains ``model`` in closed loop on ``stage``'s windows through its forward model, as
  ``smpl.training.train_inverse_model`` does, plus ``penalty()`` (a scalar tensor: EWC's
  consolidation, a replay batch's loss) on every training batch; validation is ``stage``'s
  action MSE alone. ``forwards``: further forward models the penalty runs, moved to the device
  with ``stage``'s."""
  config = setting.config

  def action_loss(windows, with_aux: bool = True):
    return training.inverse_model_loss(
      model, stage.forward, windows, config.feed_back_error, config.pose_loss_weight, with_aux
    )

  def loss(windows):
    return action_loss(windows) + (penalty() if penalty is not None else 0.0)

  with fitting.on_device(setting.device, stage.forward, *forwards):
    return fitting.fit(
      model,
      loss,
      stage.windows.train,
      stage.windows.validation,
      config,
      setting.device,
      on_epoch_end,
      lambda windows: action_loss(windows, with_aux=False),
    )


def tensors_digest(tensors: dict[str, torch.Tensor]) -> str:
  """sha256 of named tensors (names, dtypes, shapes and bytes)."""
  digest = hashlib.sha256()
  for name, tensor in tensors.items():
    value = tensor.detach().cpu().contiguous()
    digest.update(f"{name}|{value.dtype}|{tuple(value.shape)}|".encode())
    digest.update(value.numpy().tobytes())
  return digest.hexdigest()
