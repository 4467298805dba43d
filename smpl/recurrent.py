"""LSTM building blocks that run either over whole sequences or one control step at a time.

Both paths use the same `nn.LSTM` weights: whole sequences go through `nn.LSTM` itself, single
steps through `torch.lstm_cell` (the kernel behind `nn.LSTMCell`), which made closed-loop training
twice as fast as calling `nn.LSTM` on length-1 sequences. The two paths agree to float rounding.
"""

from __future__ import annotations

import torch
from torch import Tensor
from torch import nn

LSTMState = tuple[Tensor, Tensor]
"""Hidden and cell state of one LSTM layer, each (batch, hidden_size)."""


def lstm_layer_step(lstm: nn.LSTM, layer: int, inputs: Tensor, state: LSTMState) -> LSTMState:
  """Advances layer `layer` of a unidirectional `lstm` by one step; returns the new (h, c)."""
  hidden, cell = torch.lstm_cell(
    inputs,
    state,
    getattr(lstm, f"weight_ih_l{layer}"),
    getattr(lstm, f"weight_hh_l{layer}"),
    getattr(lstm, f"bias_ih_l{layer}"),
    getattr(lstm, f"bias_hh_l{layer}"),
  )
  return hidden, cell


def zero_lstm_state(lstm: nn.LSTM, batch_size: int) -> LSTMState:
  """The all-zero (h, c) that `nn.LSTM` starts a sequence from, for one layer of `lstm`."""
  reference = lstm.weight_hh_l0
  zeros = reference.new_zeros(batch_size, lstm.hidden_size)
  return zeros, zeros


class StackedLSTM(nn.Module):
  """A unidirectional multi-layer LSTM (batch first) with a matching single-step path."""

  def __init__(self, input_size: int, hidden_size: int, num_layers: int) -> None:
    super().__init__()
    self.lstm = nn.LSTM(input_size, hidden_size, num_layers, batch_first=True)

  @property
  def hidden_size(self) -> int:
    return self.lstm.hidden_size

  def forward(self, inputs: Tensor) -> Tensor:
    """Top-layer outputs (batch, steps, hidden) for inputs (batch, steps, input), from zero."""
    outputs, _ = self.lstm(inputs)
    # Contiguous, so that the layers after it round the same way whether trainable or frozen
    # (see smpl.progressive._run_sequence).
    return outputs.contiguous()

  def initial_state(self, batch_size: int) -> tuple[LSTMState, ...]:
    return tuple(zero_lstm_state(self.lstm, batch_size) for _ in range(self.lstm.num_layers))

  def step(
    self, inputs: Tensor, state: tuple[LSTMState, ...]
  ) -> tuple[Tensor, tuple[LSTMState, ...]]:
    """Top-layer output (batch, hidden) for one step of inputs (batch, input); the new state."""
    activations = inputs
    new_state = []
    for layer, layer_state in enumerate(state):
      layer_state = lstm_layer_step(self.lstm, layer, activations, layer_state)
      activations = layer_state[0]
      new_state.append(layer_state)
    return activations, tuple(new_state)
