"""An example learned baseline for the registry test: a linear inverse model, trained on babbling
in closed loop like every baseline. With one registry line (``test_registries.py``) it is an
agent: no wrapper file, no hyperparameters entry (it trains with its defaults)."""

import torch
from torch import nn

from smpl.inverse import InverseModel
from smpl.inverse import InverseStep


class LinearInverse(InverseModel):
  """Actions as a linear function of the inputs (target, error, previous action), squashed."""

  def __init__(self, input_size: int, action_size: int) -> None:
    super().__init__()
    self.input_size, self.action_size = input_size, action_size
    self.layer = nn.Linear(input_size, action_size)

  def forward(self, inputs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    actions = torch.tanh(self.layer(inputs))
    return actions, actions.new_zeros(())

  def initial_state(self, batch_size: int) -> None:
    return None

  def step(self, inputs: torch.Tensor, state: None) -> InverseStep:
    action = torch.tanh(self.layer(inputs))
    return InverseStep(action, action.new_zeros(()), None)
