"""The learned baselines the paper compares SMPL with, all behind the InverseModel interface.

The sizes below are the constructors' defaults. The agents build these models with the values
committed in `softbench/agents/hyperparameters.json`, chosen on validation data with Optuna as in
the paper (`softbench tune`); these defaults were the first trial of each study.
"""

from __future__ import annotations

import torch
from torch import Tensor
from torch import nn
from torch.nn.utils.rnn import pack_padded_sequence

from smpl.inverse import InverseModel
from smpl.inverse import InverseStep
from smpl.recurrent import LSTMState
from smpl.recurrent import StackedLSTM
from smpl.windows import SEQUENCE_LENGTH

MLP_HIDDEN_SIZE = 64
"""Units per hidden layer of the MLP baseline."""
MLP_HIDDEN_LAYERS = 3
"""Hidden layers of the MLP baseline (paper: a 3-layer MLP)."""
LSTM_HIDDEN_SIZE = 32
"""LSTM units per layer of the recurrent baselines, as in one SMPL column."""
LSTM_LAYERS = 2
"""LSTM layers of the recurrent baselines, as in one SMPL column."""
VAE_LATENT_SIZE = 8
"""Latent dimensions of the VAE-LSTM baseline."""
VAE_KL_WEIGHT = 1e-3
"""beta: weight of the KL divergence in the VAE-LSTM training loss."""


class MLPInverse(InverseModel):
  """A memoryless perceptron; the error and previous action inputs are its only history."""

  def __init__(
    self,
    input_size: int,
    action_size: int,
    hidden_size: int = MLP_HIDDEN_SIZE,
    num_hidden_layers: int = MLP_HIDDEN_LAYERS,
  ) -> None:
    super().__init__()
    self.input_size = input_size
    self.action_size = action_size
    layers: list[nn.Module] = []
    width = input_size
    for _ in range(num_hidden_layers):
      layers += [nn.Linear(width, hidden_size), nn.Tanh()]
      width = hidden_size
    layers.append(nn.Linear(width, action_size))
    self.network = nn.Sequential(*layers)

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    actions = self.network(inputs)
    return actions, actions.new_zeros(())

  def initial_state(self, batch_size: int) -> None:
    return None

  def step(self, inputs: Tensor, state: None) -> InverseStep:
    action = self.network(inputs)
    return InverseStep(action, action.new_zeros(()), None)


class LSTMInverse(InverseModel):
  """A stacked LSTM with a linear head: one SMPL column without lateral connections."""

  def __init__(
    self,
    input_size: int,
    action_size: int,
    hidden_size: int = LSTM_HIDDEN_SIZE,
    num_layers: int = LSTM_LAYERS,
  ) -> None:
    super().__init__()
    self.input_size = input_size
    self.action_size = action_size
    self.recurrent = StackedLSTM(input_size, hidden_size, num_layers)
    self.head = nn.Linear(hidden_size, action_size)

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    actions = self.head(self.recurrent(inputs))
    return actions, actions.new_zeros(())

  def initial_state(self, batch_size: int) -> tuple[LSTMState, ...]:
    return self.recurrent.initial_state(batch_size)

  def step(self, inputs: Tensor, state: tuple[LSTMState, ...]) -> InverseStep:
    hidden, state = self.recurrent.step(inputs, state)
    action = self.head(hidden)
    return InverseStep(action, action.new_zeros(()), state)


class VAELSTMInverse(InverseModel):
  """A variational LSTM: encoder LSTM -> (mean, log-variance) -> latent sample -> decoder.

  In training mode the latent is drawn with the reparameterisation trick; in eval mode it is the
  mean, so control is deterministic. The aux loss is kl_weight (beta) times the KL divergence
  from the unit Gaussian, summed over latent dimensions and averaged over batch and steps.
  """

  def __init__(
    self,
    input_size: int,
    action_size: int,
    hidden_size: int = LSTM_HIDDEN_SIZE,
    num_layers: int = LSTM_LAYERS,
    latent_size: int = VAE_LATENT_SIZE,
    kl_weight: float = VAE_KL_WEIGHT,
  ) -> None:
    super().__init__()
    self.input_size = input_size
    self.action_size = action_size
    self.kl_weight = kl_weight
    self.encoder = StackedLSTM(input_size, hidden_size, num_layers)
    self.to_latent = nn.Linear(hidden_size, 2 * latent_size)
    self.decoder = nn.Sequential(
      nn.Linear(latent_size, hidden_size), nn.Tanh(), nn.Linear(hidden_size, action_size)
    )

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    return self._decode(self.encoder(inputs))

  def initial_state(self, batch_size: int) -> tuple[LSTMState, ...]:
    return self.encoder.initial_state(batch_size)

  def step(self, inputs: Tensor, state: tuple[LSTMState, ...]) -> InverseStep:
    encoded, state = self.encoder.step(inputs, state)
    action, kl_loss = self._decode(encoded)
    return InverseStep(action, kl_loss, state)

  def _decode(self, encoded: Tensor) -> tuple[Tensor, Tensor]:
    mean, log_variance = self.to_latent(encoded).chunk(2, dim=-1)
    latent = mean
    if self.training:
      latent = mean + torch.randn_like(mean) * (0.5 * log_variance).exp()
    kl_divergence = 0.5 * (mean.square() + log_variance.exp() - 1.0 - log_variance)
    return self.decoder(latent), self.kl_weight * kl_divergence.sum(dim=-1).mean()


class BiLSTMInverse(InverseModel):
  """A bidirectional LSTM over a sliding window of the most recent inputs.

  A controller cannot see future targets, so the action at step t summarises only the inputs of
  steps max(0, t - window + 1) .. t: the final hidden states of the forward direction (having
  read the window oldest first) and of the backward direction (newest first) feed a linear head.
  Step-wise, the state is the window of past inputs, and each step re-reads it in both
  directions; `forward` does the same for every step of a sequence at once.
  """

  compiles_on_cpu = False  # nn.LSTM's fused CPU kernel: see `ForwardModel.compiles_on_cpu`.

  def __init__(
    self,
    input_size: int,
    action_size: int,
    hidden_size: int = LSTM_HIDDEN_SIZE,
    num_layers: int = LSTM_LAYERS,
    window: int = SEQUENCE_LENGTH,
  ) -> None:
    super().__init__()
    self.input_size = input_size
    self.action_size = action_size
    self.window = window
    self.lstm = nn.LSTM(input_size, hidden_size, num_layers, batch_first=True, bidirectional=True)
    self.head = nn.Linear(2 * hidden_size, action_size)

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    batch_size, steps, _ = inputs.shape
    lengths = [min(step + 1, self.window) for step in range(steps)]
    longest = max(lengths)
    # windows[b, t] = inputs[b, t-length+1 .. t], right-padded to the longest window.
    windows = torch.stack(
      [
        nn.functional.pad(inputs[:, step + 1 - length : step + 1], (0, 0, 0, longest - length))
        for step, length in enumerate(lengths)
      ],
      dim=1,
    )
    packed = pack_padded_sequence(
      windows.reshape(batch_size * steps, longest, -1),
      torch.tensor(lengths).repeat(batch_size),
      batch_first=True,
      enforce_sorted=False,
    )
    actions = self._summarise(packed).reshape(batch_size, steps, -1)
    return actions, actions.new_zeros(())

  def initial_state(self, batch_size: int) -> Tensor:
    """An empty window of past inputs, (batch, 0, input_size)."""
    return self.head.weight.new_zeros(batch_size, 0, self.input_size)

  def step(self, inputs: Tensor, state: Tensor) -> InverseStep:
    window = torch.cat([state, inputs[:, None]], dim=1)[:, -self.window :]
    action = self._summarise(window)
    return InverseStep(action, action.new_zeros(()), window)

  def _summarise(self, windows: Tensor | nn.utils.rnn.PackedSequence) -> Tensor:
    _, (final_hidden, _) = self.lstm(windows)
    # final_hidden is (layers * 2, batch, hidden); the last two rows are the top layer's
    # forward and backward directions.
    return self.head(torch.cat([final_hidden[-2], final_hidden[-1]], dim=-1))
