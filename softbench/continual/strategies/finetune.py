"""``finetune``: one shared network (``softbench.continual.networks``) trained on each stage's
data in turn, nothing done to keep what earlier stages taught it: the lower bound of remembering."""

from softbench.continual.strategies import base
from softbench.continual.strategies import shared


class Finetune(shared.SharedNetwork):
  def learn(self, stage, stages, on_epoch_end) -> base.StageTraining:
    model = self.controller(stage)
    result = base.fit_configuration(
      model, stages[stage], self.setting, on_epoch_end, *self.regulariser(stage, stages)
    )
    return base.StageTraining((result,), self.trained_on(stage))

  def regulariser(self, stage: int, stages: list) -> tuple:
    """(penalty, its forward models) added to stage ``stage``'s loss: none here."""
    return None, ()

  def trained_on(self, stage: int) -> tuple[int, ...]:
    """The configurations whose data stage ``stage`` reads."""
    return (stage,)


STRATEGY = Finetune
