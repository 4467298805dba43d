"""``independent``: a fresh network per configuration, trained on its data alone and never
touched again (no transfer, no forgetting): the reference of forward transfer. Each network is
one SMPL column's LSTM (``smpl.baselines.LSTMInverse``, 2 x 32 units) sized for its
configuration, seeded by the run's seed plus the stage, as SMPL's columns are."""

from torch import nn

from smpl import baselines
from smpl import windows as smpl_windows
from softbench.continual.strategies import base


class Independent(base.Strategy):
  def __init__(self, setting: base.Setting) -> None:
    super().__init__(setting)
    self.module.networks = nn.ModuleList()

  def grow(self, stage: int) -> None:
    size = self.setting.action_sizes[stage]
    input_size = smpl_windows.inverse_input_size(self.setting.pose_size, size)
    self.module.networks.append(
      self.new_seeded(stage, lambda: baselines.LSTMInverse(input_size, size))
    )

  def learn(self, stage, stages, on_epoch_end) -> base.StageTraining:
    network = self.module.networks[stage]
    result = base.fit_configuration(network, stages[stage], self.setting, on_epoch_end)
    network.requires_grad_(False)
    return base.StageTraining((result,), (stage,))

  def controller(self, configuration: int):
    return self.module.networks[configuration].eval()


STRATEGY = Independent
