"""``smpl``: the progressive network, a new LSTM column per configuration, the earlier columns
frozen (``smpl.protocol.train_next_column``); configuration c acts with column c, reading columns
0..c-1 through its lateral connections. On ``grow`` this is Exp1S."""

import torch

from smpl import fitting
from smpl import progressive
from smpl import training
from smpl import windows as smpl_windows
from softbench.continual.strategies import base


class Progressive(base.Strategy):
  def __init__(self, setting: base.Setting) -> None:
    super().__init__(setting)
    self.module.network = progressive.ProgressiveLSTM()

  def grow(self, stage: int) -> None:
    # train_next_column seeds column k with the seed plus k; a cached state loads into it.
    network = self.module.network
    size = self.setting.action_sizes[stage]
    with fitting.seeded(self.setting.seed + network.num_columns, torch.device("cpu")):
      network.add_column(smpl_windows.inverse_input_size(self.setting.pose_size, size), size)

  def learn(self, stage, stages, on_epoch_end) -> base.StageTraining:
    data = stages[stage]
    windows = data.windows
    result = training.train_inverse_model(
      self.module.network,
      data.forward,
      windows.train,
      windows.validation,
      self.setting.config,
      self.setting.device,
      on_epoch_end,
    )
    self.module.network.requires_grad_(False)
    return base.StageTraining((result,), (stage,))

  def controller(self, configuration: int):
    return self.module.network.column_model(configuration).eval()

  def controller_digest(self, configuration: int) -> str:
    """Columns 0..c only: the later ones do not reach column c's actions."""
    columns = self.module.network.columns[: configuration + 1]
    return base.tensors_digest(columns.state_dict())


STRATEGY = Progressive
