"""One network for every configuration of a stream: the learner of ``finetune``, ``ewc``,
``replay`` and ``joint``.

The shared network is an LSTM of one SMPL column's size (``smpl.baselines.LSTMInverse``: 2 layers
of 32 units and a linear head) whose input and output are sized for the stream's largest
configuration, with the configuration as a one-hot code: its input is

    [target pose, pose error, previous action padded with zeros to A, one-hot configuration]

and configuration c acts with the first ``a_c`` of its A outputs (the others are masked: no loss
reaches them from c). Action entry i is the same actuator role in every configuration (module
k's cables are entries 2k-2, 2k-1 in every tendon arm that has module k), so the shared output
units are where both transfer and interference happen; one head per configuration would hide
forgetting in heads the later stages never touch, and the input would need padding anyway. The
code tells the network which configuration it drives, as SMPL knows by its column (with the
module count as the paper's Bi-LSTM of Chen et al. 2024 reads it, for ``grow``).

``ConfiguredModel`` is the shared network seen as configuration c's inverse model
(``smpl.inverse.InverseModel``), so it trains through ``smpl.training`` and acts through
``softbench.agents.learned`` unchanged.
"""

import torch
from torch import Tensor

from smpl import baselines
from smpl import windows as smpl_windows
from smpl.inverse import InverseModel
from smpl.inverse import InverseStep


def shared_network(pose_size: int, action_sizes: list[int]) -> baselines.LSTMInverse:
  """An untrained shared network for configurations with ``action_sizes`` (seed torch first)."""
  largest = max(action_sizes)
  code_size = len(action_sizes)
  return baselines.LSTMInverse(
    smpl_windows.inverse_input_size(pose_size, largest) + code_size, largest
  )


class ConfiguredModel(InverseModel):
  """The shared network driving configuration ``configuration`` (module docstring)."""

  def __init__(
    self,
    network: baselines.LSTMInverse,
    configuration: int,
    pose_size: int,
    action_sizes: list[int],
  ) -> None:
    super().__init__()
    self.network = network
    self.configuration = configuration
    self.pose_size = pose_size
    self.action_size = action_sizes[configuration]
    self.input_size = smpl_windows.inverse_input_size(pose_size, self.action_size)
    self._padding = max(action_sizes) - self.action_size
    self._code = torch.zeros(len(action_sizes))
    self._code[configuration] = 1.0

  def shared_inputs(self, inputs: Tensor) -> Tensor:
    """``inputs`` of this configuration (..., input_size) as the shared network reads them."""
    leading = inputs.shape[:-1]
    padding = inputs.new_zeros(*leading, self._padding)
    code = self._code.to(inputs.device, inputs.dtype).expand(*leading, -1)
    return torch.cat([inputs, padding, code], dim=-1)

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    actions, aux_loss = self.network(self.shared_inputs(inputs))
    return actions[..., : self.action_size], aux_loss

  def initial_state(self, batch_size: int):
    return self.network.initial_state(batch_size)

  def step(self, inputs: Tensor, state) -> InverseStep:
    step = self.network.step(self.shared_inputs(inputs), state)
    return InverseStep(step.action[..., : self.action_size], step.aux_loss, step.state)
