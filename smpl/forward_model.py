"""The learned forward model x'_{t+1} = f(x_{t-1}, x_t, actuation_t) closing the training loop."""

from __future__ import annotations

import torch
from torch import Tensor
from torch import nn

from smpl.recurrent import LSTMState
from smpl.recurrent import StackedLSTM

HIDDEN_SIZE = 64
"""LSTM units per layer (paper, forward model)."""
LSTM_LAYERS = 2
"""LSTM layers (paper, forward model)."""
POSE_SIZE = 6
"""Tip position (3) and the tip frame's z-axis in world coordinates (3)."""

ForwardState = tuple[LSTMState, ...]


class ForwardModel(nn.Module):
  """Predicts the next pose from the previous pose, the current pose and the current actuation.

  The actuation is that of the module and of every module before it (the forward model of module
  k sees the coupling from modules 1..k-1). Once trained it is frozen, but stays differentiable
  with respect to its inputs so that inverse-model training can backpropagate through it.
  """

  compiles_on_cpu = False
  """Inductor (torch 2.13) cannot compile the CPU's fused nn.LSTM (`aten.mkldnn_rnn_layer`
    fails with "expected Tensor()"), which this model runs over whole windows; `smpl.fitting.fit`
    trains it eagerly on the CPU rather than fail, warn and fall back."""

  def __init__(
    self,
    actuation_size: int,
    pose_size: int = POSE_SIZE,
    hidden_size: int = HIDDEN_SIZE,
    num_layers: int = LSTM_LAYERS,
  ) -> None:
    super().__init__()
    self.actuation_size = actuation_size
    self.pose_size = pose_size
    self.recurrent = StackedLSTM(2 * pose_size + actuation_size, hidden_size, num_layers)
    self.head = nn.Linear(hidden_size, pose_size)

  def forward(self, previous_poses: Tensor, current_poses: Tensor, actuations: Tensor) -> Tensor:
    """Next poses (batch, steps, pose) for whole sequences, starting from the zero state."""
    inputs = torch.cat([previous_poses, current_poses, actuations], dim=-1)
    return self.head(self.recurrent(inputs))

  def initial_state(self, batch_size: int) -> ForwardState:
    return self.recurrent.initial_state(batch_size)

  def step(
    self, previous_pose: Tensor, current_pose: Tensor, actuation: Tensor, state: ForwardState
  ) -> tuple[Tensor, ForwardState]:
    """Next pose (batch, pose) for one step, and the new state."""
    inputs = torch.cat([previous_pose, current_pose, actuation], dim=-1)
    hidden, state = self.recurrent.step(inputs, state)
    return self.head(hidden), state

  def freeze(self) -> ForwardModel:
    """Stops training of every weight; returns self."""
    self.requires_grad_(False)
    self.eval()
    return self

  @property
  def is_frozen(self) -> bool:
    return not any(parameter.requires_grad for parameter in self.parameters())
