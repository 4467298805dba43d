"""``replay``: the shared network of ``finetune``, every training batch joined by a batch of the
same size drawn from a fixed buffer of earlier stages' training windows, each window scored in
closed loop through its own configuration's forward model (experience replay with a balanced
buffer: at stage s each earlier stage keeps ``BUFFER_WINDOWS // s`` windows, drawn at random
once per run and seed). The replay batch's action MSE is added to the stage's with equal weight."""

import torch

from smpl import training
from softbench.continual.strategies import base
from softbench.continual.strategies import finetune

BUFFER_WINDOWS = 1000  # Earlier stages' windows kept in all (a quarter of a default stage's).


class Replay(finetune.Finetune):
  @classmethod
  def constants(cls) -> dict:
    return {"buffer_windows": BUFFER_WINDOWS}

  def regulariser(self, stage: int, stages: list) -> tuple:
    if stage == 0:
      return None, ()
    device = self.setting.device
    kept = BUFFER_WINDOWS // stage
    buffers = [
      (c, self._kept_windows(c, stages[c], kept).to(device), self.controller(c))
      for c in range(stage)
    ]
    sizes = torch.tensor([len(windows) for _, windows, _ in buffers])
    starts = torch.cumsum(sizes, 0) - sizes
    drawing = torch.Generator().manual_seed(self.setting.seed * 1_000 + stage)
    config = self.setting.config

    def penalty() -> torch.Tensor:
      drawn = torch.randint(int(sizes.sum()), (config.batch_size,), generator=drawing)
      owner = torch.searchsorted(starts, drawn, right=True) - 1
      loss = 0.0
      for c, windows, model in buffers:
        picked = drawn[owner == c] - starts[c]
        if len(picked):
          part = training.inverse_model_loss(
            model, stages[c].forward, windows.subset(picked.to(device)), config.feed_back_error
          )
          loss = loss + part * len(picked) / config.batch_size
      return loss

    return penalty, tuple(stages[c].forward for c in range(stage))

  def trained_on(self, stage: int) -> tuple[int, ...]:
    return tuple(range(stage + 1))

  def _kept_windows(self, configuration: int, data: base.StageData, count: int):
    """The ``count`` windows of ``configuration``'s training split in the buffer."""
    windows = data.windows.train
    order = torch.randperm(
      len(windows),
      generator=torch.Generator().manual_seed(self.setting.seed * 1_000 + configuration),
    )
    return windows.subset(order[: min(count, len(windows))])


STRATEGY = Replay
