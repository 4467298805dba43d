"""A continual strategy and a stream from outside softbench, registered by the tests
(``softbench.continual.strategies.register``, ``softbench.continual.streams.register``).

``first-only`` learns the first configuration and drives every later one with that network,
untouched: what a controller that never adapts keeps. It needs configurations of one action
size, so it refuses streams that grow or shrink the arm."""

from smpl import baselines
from smpl import windows as smpl_windows
from softbench import robots
from softbench.continual import strategies
from softbench.continual import streams
from softbench.continual.strategies import base


class FirstOnly(base.Strategy):
  @classmethod
  def check(cls, configurations) -> None:
    sizes = sorted({configuration.robot.action_dim for configuration in configurations})
    if len(sizes) > 1:
      raise ValueError(
        f"strategy first-only drives every configuration with the first one's network, so "
        f"it needs one action size; this stream's configurations have {sizes}"
      )

  def __init__(self, setting: base.Setting) -> None:
    super().__init__(setting)
    size = setting.action_sizes[0]
    self.module.network = self.new_seeded(
      0,
      lambda: baselines.LSTMInverse(smpl_windows.inverse_input_size(setting.pose_size, size), size),
    )

  def learn(self, stage, stages, on_epoch_end) -> base.StageTraining:
    if stage:
      return base.StageTraining((), ())
    result = base.fit_configuration(self.module.network, stages[0], self.setting, on_epoch_end)
    self.module.network.requires_grad_(False)
    return base.StageTraining((result,), (0,))

  def controller(self, configuration: int):
    return self.module.network.eval()


STRATEGY = FirstOnly
ENTRY = strategies.StrategyEntry(__name__, "the first configuration's network for every one")
PAYLOADS_KG = (0.0, 0.005)
LOADED = streams.Stream(
  "loaded-pair",
  "tendon-1, then carrying 5 g",
  lambda family: tuple(
    streams.Configuration(f"{kg * 1000:g} g", robots.make(f"{family}-1", payload=kg))
    for kg in PAYLOADS_KG
  ),
)
