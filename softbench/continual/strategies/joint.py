"""``joint``: not continual, the upper bound: one shared network (``softbench.continual.networks``,
the configuration as a one-hot input, as the Bi-LSTM of Chen et al. 2024 reads the module count)
trained once, at the first stage, on every configuration's data at once. Each training step
takes one batch of every configuration (the same window indices of each), and the loss and the
validation loss are the mean over configurations of their closed-loop action MSE; later stages
train nothing."""

import torch

from smpl import fitting
from smpl import training
from smpl import windows as smpl_windows
from softbench.continual.strategies import base
from softbench.continual.strategies import shared


class Joint(shared.SharedNetwork):
  continual = False

  def learn(self, stage, stages, on_epoch_end) -> base.StageTraining:
    if stage:
      return base.StageTraining((), ())
    models = [self.controller(c) for c in range(len(stages))]
    config = self.setting.config

    def loss(windows: smpl_windows.ModuleWindows, with_aux: bool = True) -> torch.Tensor:
      losses = [
        training.inverse_model_loss(
          model, data.forward, part, config.feed_back_error, config.pose_loss_weight, with_aux
        )
        for model, data, part in zip(models, stages, windows.modules)
      ]
      return sum(losses[1:], losses[0]) / len(losses)

    forwards = [data.forward for data in stages]
    with fitting.on_device(self.setting.device, *forwards):
      result = fitting.fit(
        self.module.network,
        loss,
        _aligned([data.windows.train for data in stages]),
        _aligned([data.windows.validation for data in stages]),
        config,
        self.setting.device,
        on_epoch_end,
        lambda windows: loss(windows, with_aux=False),
      )
    return base.StageTraining((result,), tuple(range(len(stages))))


def _aligned(splits: list) -> smpl_windows.ModuleWindows:
  """Every configuration's windows cut to the shortest count, so that a batch takes the same
  window indices of each."""
  count = min(len(windows) for windows in splits)
  first = torch.arange(count)
  return smpl_windows.ModuleWindows(tuple(windows.subset(first) for windows in splits))


STRATEGY = Joint
