"""``ewc``: the shared network of ``finetune`` with elastic weight consolidation (Kirkpatrick et
al. 2017). Before stage s it measures the diagonal Fisher information F_{s-1} of stage s-1's
loss at the weights that stage ended with (the anchor), and every later training batch pays

    LAMBDA / 2 * sum over earlier stages t, parameters i of F_t,i (theta_i - anchor_t,i)^2.

The Fisher is the empirical one of minibatches, as Avalanche computes it: the mean over stage
s-1's training batches (in order, the stage's batch size) of each parameter's squared gradient of
the closed-loop action MSE."""

import torch
from torch import nn

from smpl import fitting
from smpl import training
from softbench.continual.strategies import base
from softbench.continual.strategies import finetune

LAMBDA = 1.0e7  # Weight of the penalty: docs/continual.md (chosen on validation data).


class ElasticWeightConsolidation(finetune.Finetune):
  @classmethod
  def constants(cls) -> dict:
    return {"lambda": LAMBDA}

  def __init__(self, setting: base.Setting) -> None:
    super().__init__(setting)
    self.module.consolidation = nn.ModuleList()  # Per earlier stage: Fisher and anchor buffers.

  def grow(self, stage: int) -> None:
    if stage == 0:
      return
    holder = nn.Module()
    for index, parameter in enumerate(self.module.network.parameters()):
      holder.register_buffer(f"fisher{index}", torch.zeros_like(parameter))
      holder.register_buffer(f"anchor{index}", torch.zeros_like(parameter))
    self.module.consolidation.append(holder)

  def regulariser(self, stage: int, stages: list) -> tuple:
    if stage == 0:
      return None, ()
    self._consolidate(stage - 1, stages[stage - 1])
    parameters = list(self.module.network.parameters())
    device = self.setting.device
    terms = [
      [
        (getattr(holder, f"fisher{i}").to(device), getattr(holder, f"anchor{i}").to(device))
        for i in range(len(parameters))
      ]
      for holder in self.module.consolidation
    ]

    def penalty() -> torch.Tensor:
      total = sum(
        (fisher * (parameter - anchor) ** 2).sum()
        for stage_terms in terms
        for parameter, (fisher, anchor) in zip(parameters, stage_terms)
      )
      return LAMBDA / 2 * total

    return penalty, ()

  def trained_on(self, stage: int) -> tuple[int, ...]:
    return (stage - 1, stage) if stage else (stage,)  # The Fisher reads the previous stage's.

  def _consolidate(self, stage: int, data: base.StageData) -> None:
    """Fills stage ``stage``'s Fisher and anchor (module docstring)."""
    holder = self.module.consolidation[stage]
    model = self.controller(stage)
    parameters = list(self.module.network.parameters())
    sums = [torch.zeros_like(parameter) for parameter in parameters]
    config = self.setting.config
    windows = data.windows.train
    batches = torch.arange(len(windows)).split(config.batch_size)
    with fitting.limited_cpu_threads(config.cpu_threads, torch.device("cpu")):
      for indices in batches:
        model.zero_grad(set_to_none=True)
        training.inverse_model_loss(
          model, data.forward, windows.subset(indices), config.feed_back_error
        ).backward()
        for total, parameter in zip(sums, parameters):
          total += parameter.grad.detach() ** 2
    model.zero_grad(set_to_none=True)
    for index, (total, parameter) in enumerate(zip(sums, parameters)):
      getattr(holder, f"fisher{index}").copy_(total / len(batches))
      getattr(holder, f"anchor{index}").copy_(parameter.detach())


STRATEGY = ElasticWeightConsolidation
