"""What the strategies of one shared network (``finetune``, ``ewc``, ``replay``, ``joint``) have in
common: the network (``softbench.continual.networks``, seeded by the run's seed) and each
configuration's view of it."""

from softbench.continual import networks
from softbench.continual.strategies import base


class SharedNetwork(base.Strategy):
  def __init__(self, setting: base.Setting) -> None:
    super().__init__(setting)
    self.module.network = self.new_seeded(
      0, lambda: networks.shared_network(setting.pose_size, list(setting.action_sizes))
    )

  def controller(self, configuration: int):
    return networks.ConfiguredModel(
      self.module.network, configuration, self.setting.pose_size, list(self.setting.action_sizes)
    ).eval()
