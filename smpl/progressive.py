"""SMPL's progressive neural network: one LSTM column per configuration or module.

Hidden layer i of column k computes (paper, Eq. "hidden_out")

    h_i^k = f( W_i^k h_{i-1}^k + sum_{j<k} L_i^{k:j} h_{i-1}^j ),

with lateral connections into every layer after the first and into the linear head. Here f is an
LSTM layer and the lateral term is added to the layer's input: the input of LSTM layer i of column
k is h_{i-1}^k + L_i^k [h_{i-1}^0, ..., h_{i-1}^{k-1}], where the lateral map L_i^k is one bias-free
`nn.Linear` over the concatenated outputs of the earlier columns (its j-th block of input columns
is L_i^{k:j}). The head of column k reads its last LSTM layer the same way. The laterals carry no
bias because the LSTM layer and the head that read them already have one.

Adding a column freezes every earlier one. Column k reads only columns 0..k, so the output of an
earlier column is bit-identical however many columns come after it, which is what lets a detached
module fall back to its old column without retraining.
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Sequence
from dataclasses import dataclass

import torch
from torch import Tensor
from torch import nn

from smpl.inverse import InverseModel
from smpl.inverse import InverseStep
from smpl.recurrent import LSTMState
from smpl.recurrent import lstm_layer_step
from smpl.recurrent import zero_lstm_state

HIDDEN_SIZE = 32
"""LSTM units per layer of a column (paper, SMPL training)."""
LSTM_LAYERS = 2
"""LSTM layers per column (paper, SMPL training)."""

ColumnState = tuple[LSTMState, ...]
"""(h, c) of each LSTM layer of one column."""
_RunLayer = Callable[[nn.LSTM, Tensor, LSTMState | None], tuple[Tensor, LSTMState | None]]


@dataclass(frozen=True)
class ProgressiveLSTMConfig:
  """Everything needed to rebuild a ProgressiveLSTM before loading its weights."""

  hidden_size: int = HIDDEN_SIZE
  num_lstm_layers: int = LSTM_LAYERS
  column_sizes: tuple[tuple[int, int], ...] = ()
  """(input_size, output_size) of each column, in the order they were added."""


class _Column(nn.Module):
  """LSTM layers and a linear head, plus lateral maps from the columns before it."""

  def __init__(
    self,
    input_size: int,
    output_size: int,
    hidden_size: int,
    num_lstm_layers: int,
    num_earlier_columns: int,
  ) -> None:
    super().__init__()
    self.input_size = input_size
    self.output_size = output_size
    self.lstm_layers = nn.ModuleList(
      nn.LSTM(input_size if layer == 0 else hidden_size, hidden_size, batch_first=True)
      for layer in range(num_lstm_layers)
    )
    # laterals[i] carries the earlier columns' outputs of LSTM layer i into this column's
    # next LSTM layer, or into the head after the last layer. The first column has none.
    self.laterals = nn.ModuleList(
      nn.Linear(num_earlier_columns * hidden_size, hidden_size, bias=False)
      for _ in range(num_lstm_layers if num_earlier_columns else 0)
    )
    self.head = nn.Linear(hidden_size, output_size)

  def next_layer_input(
    self, layer: int, own_hidden: Tensor, earlier_hidden: list[Tensor]
  ) -> Tensor:
    """Input to the layer after `layer`: own output plus the lateral map of earlier columns'."""
    if not earlier_hidden:
      return own_hidden
    return own_hidden + self.laterals[layer](torch.cat(earlier_hidden, dim=-1))


class ProgressiveLSTM(InverseModel):
  """A progressive network of LSTM columns; see the module docstring.

  Inputs are given either as one tensor per column (columns may differ in input size), or as a
  single tensor for the chosen column from which every earlier column reads the leading features
  it needs, zero-padded on the right if it reads more. A shared tensor suits Exp1S: with inputs
  [target, error, previous action of modules 1..k], column j < k reads [target, error, previous
  action of modules 1..j]. One tensor per column suits Exp2S/Exp2R, where column k reads
  module k's own target, error and previous action (`step_columns` runs them together).
  """

  def __init__(self, hidden_size: int = HIDDEN_SIZE, num_lstm_layers: int = LSTM_LAYERS) -> None:
    super().__init__()
    self.hidden_size = hidden_size
    self.num_lstm_layers = num_lstm_layers
    self.columns = nn.ModuleList()

  @classmethod
  def from_config(cls, config: ProgressiveLSTMConfig) -> ProgressiveLSTM:
    network = cls(config.hidden_size, config.num_lstm_layers)
    for input_size, output_size in config.column_sizes:
      network.add_column(input_size, output_size)
    return network

  @property
  def config(self) -> ProgressiveLSTMConfig:
    return ProgressiveLSTMConfig(
      self.hidden_size,
      self.num_lstm_layers,
      tuple((column.input_size, column.output_size) for column in self.columns),
    )

  @property
  def num_columns(self) -> int:
    return len(self.columns)

  @property
  def input_size(self) -> int:
    return self._column(-1).input_size

  @property
  def action_size(self) -> int:
    return self._column(-1).output_size

  def add_column(self, input_size: int, output_size: int) -> int:
    """Freezes every existing column and appends a new trainable one; returns its index."""
    self.columns.requires_grad_(False)
    column = _Column(
      input_size, output_size, self.hidden_size, self.num_lstm_layers, self.num_columns
    )
    if self.num_columns:
      column.to(next(self.columns.parameters()).device)
    self.columns.append(column)
    return self.num_columns - 1

  def column_model(self, column: int) -> ProgressiveColumn:
    """Column `column` (and the earlier ones it reads) as a stand-alone inverse model."""
    return ProgressiveColumn(self, self._column_index(column))

  def column_outputs(self, inputs: Tensor | Sequence[Tensor], upto: int = -1) -> list[Tensor]:
    """Outputs (batch, steps, output_size_k) of columns 0..upto for whole sequences."""
    column = self._column_index(upto)
    column_inputs = self._route(inputs, column)
    no_states = [(None,) * self.num_lstm_layers] * len(column_inputs)
    outputs, _ = self._propagate(column_inputs, no_states, _run_sequence)
    return outputs

  def forward(self, inputs: Tensor | Sequence[Tensor], column: int = -1) -> tuple[Tensor, Tensor]:
    """Output of one column (default: the last) for whole sequences, and a zero aux loss."""
    actions = self.column_outputs(inputs, column)[-1]
    return actions, actions.new_zeros(())

  def initial_state(self, batch_size: int, column: int = -1) -> tuple[ColumnState, ...]:
    """Zero state of columns 0..column."""
    return tuple(
      tuple(zero_lstm_state(lstm, batch_size) for lstm in self.columns[index].lstm_layers)
      for index in range(self._column_index(column) + 1)
    )

  def step(
    self,
    inputs: Tensor | Sequence[Tensor],
    state: tuple[ColumnState, ...],
    column: int = -1,
  ) -> InverseStep:
    """One control step of column `column`; `state` holds columns 0..column."""
    column = self._column_index(column)
    if len(state) != column + 1:
      raise ValueError(f"state holds {len(state)} columns, column {column} needs {column + 1}")
    actions, new_state = self.step_columns(inputs, state, column)
    action = actions[-1]
    return InverseStep(action, action.new_zeros(()), new_state)

  def step_columns(
    self,
    inputs: Tensor | Sequence[Tensor],
    state: tuple[ColumnState, ...],
    column: int = -1,
  ) -> tuple[list[Tensor], tuple[ColumnState, ...]]:
    """One control step of columns 0..`column` at once: every column's output and the new
    state. With one input per column (each module's own target, error and previous action),
    this is the distributed controller of Exp2S/Exp2R acting on the whole arm."""
    column = self._column_index(column)
    if len(state) != column + 1:
      raise ValueError(f"state holds {len(state)} columns, column {column} needs {column + 1}")
    return self._propagate(self._route(inputs, column), state, _run_step)

  def _propagate(
    self,
    column_inputs: list[Tensor],
    column_states: Sequence[Sequence[LSTMState | None]],
    run_layer: _RunLayer,
  ) -> tuple[list[Tensor], tuple[ColumnState, ...]]:
    """Runs columns 0..len(column_inputs)-1 in order, feeding each the earlier ones' layers."""
    outputs = []
    new_states = []
    earlier_hidden: list[list[Tensor]] = []  # [column][layer] outputs of the columns so far
    columns = self.columns[: len(column_inputs)]
    for column, activations, states in zip(columns, column_inputs, column_states, strict=True):
      hidden_per_layer = []
      new_column_state = []
      for layer, (lstm, state) in enumerate(zip(column.lstm_layers, states, strict=True)):
        hidden, state = run_layer(lstm, activations, state)
        activations = column.next_layer_input(
          layer, hidden, [hiddens[layer] for hiddens in earlier_hidden]
        )
        hidden_per_layer.append(hidden)
        new_column_state.append(state)
      outputs.append(column.head(activations))
      earlier_hidden.append(hidden_per_layer)
      new_states.append(tuple(new_column_state))
    return outputs, tuple(new_states)

  def _route(self, inputs: Tensor | Sequence[Tensor], column: int) -> list[Tensor]:
    """Per-column inputs for columns 0..column (see the class docstring)."""
    columns = self.columns[: column + 1]
    if isinstance(inputs, Tensor):
      width = inputs.shape[-1]
      if width != columns[-1].input_size:
        raise ValueError(
          f"column {column} reads {columns[-1].input_size} input features, got {width}"
        )
      return [_fit_width(inputs, earlier.input_size) for earlier in columns]
    if len(inputs) < column + 1:
      raise ValueError(f"column {column} needs inputs for {column + 1} columns, got {len(inputs)}")
    for index, (earlier, column_input) in enumerate(
      zip(columns, inputs[: column + 1], strict=True)
    ):
      if column_input.shape[-1] != earlier.input_size:
        raise ValueError(
          f"column {index} reads {earlier.input_size} input features, got {column_input.shape[-1]}"
        )
    return list(inputs[: column + 1])

  def _column_index(self, column: int) -> int:
    if not self.columns:
      raise ValueError("the network has no columns yet; call add_column first")
    return range(self.num_columns)[column]

  def _column(self, column: int) -> _Column:
    return self.columns[self._column_index(column)]


class ProgressiveColumn(InverseModel):
  """One column of a ProgressiveLSTM (reading the columns before it) as an inverse model."""

  def __init__(self, network: ProgressiveLSTM, column: int) -> None:
    super().__init__()
    self.network = network
    self.column = column

  @property
  def input_size(self) -> int:
    return self.network.columns[self.column].input_size

  @property
  def action_size(self) -> int:
    return self.network.columns[self.column].output_size

  def forward(self, inputs: Tensor | Sequence[Tensor]) -> tuple[Tensor, Tensor]:
    return self.network(inputs, self.column)

  def initial_state(self, batch_size: int) -> tuple[ColumnState, ...]:
    return self.network.initial_state(batch_size, self.column)

  def step(self, inputs: Tensor | Sequence[Tensor], state: tuple[ColumnState, ...]) -> InverseStep:
    return self.network.step(inputs, state, self.column)


def _fit_width(inputs: Tensor, width: int) -> Tensor:
  """The first `width` features of `inputs`, zero-padded on the right if it has fewer."""
  available = inputs.shape[-1]
  if available >= width:
    return inputs if available == width else inputs[..., :width]
  return nn.functional.pad(inputs, (0, width - available))


def _run_sequence(
  lstm: nn.LSTM, inputs: Tensor, state: LSTMState | None
) -> tuple[Tensor, LSTMState | None]:
  """Whole sequence from the zero state (`state` is always None on this path)."""
  outputs, _ = lstm(inputs)
  # nn.LSTM's batch-first output is a strided view. Linear layers fed a strided 3-D input pick
  # their matmul kernel by whether their weight requires grad, which would change a column's
  # rounding when it is frozen; a contiguous input always takes the same kernel.
  return outputs.contiguous(), None


def _run_step(lstm: nn.LSTM, inputs: Tensor, state: LSTMState | None) -> tuple[Tensor, LSTMState]:
  new_state = lstm_layer_step(lstm, 0, inputs, state)
  return new_state[0], new_state
