import pytest
import torch

from smpl.progressive import ProgressiveLSTM
from smpl.progressive import ProgressiveLSTMConfig

BATCH, STEPS = 4, 7
POSE = 6


def _exp1s_network(columns: int) -> ProgressiveLSTM:
  """Column k controls k + 1 two-input modules and reads [target, error, previous actions]."""
  torch.manual_seed(0)
  network = ProgressiveLSTM(hidden_size=8)
  for module_count in range(1, columns + 1):
    network.add_column(2 * POSE + 2 * module_count, 2 * module_count)
  return network


def _train_last_column(network: ProgressiveLSTM, inputs: torch.Tensor, steps: int) -> None:
  trainable = [parameter for parameter in network.parameters() if parameter.requires_grad]
  optimizer = torch.optim.Adam(trainable, lr=1e-2)
  target = torch.randn(BATCH, STEPS, network.action_size)
  network.train()
  for _ in range(steps):
    actions, _ = network(inputs)
    loss = torch.nn.functional.mse_loss(actions, target)
    optimizer.zero_grad()
    loss.backward()
    optimizer.step()


def test_old_column_outputs_are_bit_identical_after_training_a_new_column() -> None:
  network = _exp1s_network(1)
  network.train()
  inputs = torch.randn(BATCH, STEPS, 2 * POSE + 4)
  before_sequence, _ = network(inputs[..., : network.input_size])
  state = network.initial_state(BATCH)
  before_step = network.step(inputs[:, 0, : network.input_size], state).action

  network.add_column(2 * POSE + 4, 4)
  _train_last_column(network, inputs, steps=5)

  network.train()  # old columns must not depend on the mode either
  after_sequence = network.column_outputs(inputs)[0]
  assert torch.equal(after_sequence, before_sequence)
  assert torch.equal(network.column_model(0)(inputs[..., : 2 * POSE + 2])[0], before_sequence)
  state = network.initial_state(BATCH, column=0)
  assert torch.equal(
    network.step(inputs[:, 0, : 2 * POSE + 2], state, column=0).action, before_step
  )


def test_training_reaches_the_new_column_and_its_laterals_but_not_frozen_columns() -> None:
  network = _exp1s_network(3)
  frozen = {name: value.clone() for name, value in network.columns[:2].state_dict().items()}
  new_column = network.columns[2]
  lateral_before = [lateral.weight.clone() for lateral in new_column.laterals]
  inputs = torch.randn(BATCH, STEPS, network.input_size)

  actions, _ = network(inputs)
  actions.square().mean().backward()
  assert all(parameter.grad is None for parameter in network.columns[:2].parameters())
  assert all(not parameter.requires_grad for parameter in network.columns[:2].parameters())
  assert len(new_column.laterals) == network.num_lstm_layers
  for lateral in new_column.laterals:
    assert lateral.weight.grad is not None and lateral.weight.grad.abs().sum() > 0

  _train_last_column(network, inputs, steps=3)
  for name, value in network.columns[:2].state_dict().items():
    assert torch.equal(value, frozen[name]), name
  for lateral, before in zip(new_column.laterals, lateral_before, strict=True):
    assert not torch.equal(lateral.weight, before)


@pytest.mark.parametrize("columns", range(1, 7))
def test_every_column_has_its_own_input_and_output_size(columns: int) -> None:
  torch.manual_seed(columns)
  input_sizes = [3, 11, 5, 8, 2, 7][:columns]
  output_sizes = [1, 4, 2, 6, 3, 5][:columns]
  network = ProgressiveLSTM(hidden_size=8)
  for input_size, output_size in zip(input_sizes, output_sizes, strict=True):
    network.add_column(input_size, output_size)
  inputs = [torch.randn(BATCH, STEPS, size) for size in input_sizes]

  outputs = network.column_outputs(inputs)
  assert [output.shape for output in outputs] == [(BATCH, STEPS, size) for size in output_sizes]
  actions, aux_loss = network(inputs)
  assert torch.equal(actions, outputs[-1]) and aux_loss.item() == 0.0
  state = network.initial_state(BATCH)
  step = network.step([column_input[:, 0] for column_input in inputs], state)
  assert step.action.shape == (BATCH, output_sizes[-1])
  assert len(step.state) == columns


@pytest.mark.parametrize("column", [0, 2, 4])
def test_a_column_ignores_every_later_column(column: int) -> None:
  network = _exp1s_network(5)
  inputs = torch.randn(BATCH, STEPS, network.columns[column].input_size)
  before, _ = network(inputs, column=column)
  with torch.no_grad():
    for later in network.columns[column + 1 :]:
      for parameter in later.parameters():
        parameter.add_(1.0)
  after, _ = network(inputs, column=column)
  assert torch.equal(after, before)


@pytest.mark.parametrize("column", [0, 1, -1])
def test_stepwise_inference_matches_the_whole_sequence(column: int) -> None:
  network = _exp1s_network(3)
  inputs = torch.randn(BATCH, STEPS, network.columns[column].input_size)
  sequence, _ = network(inputs, column=column)
  state = network.initial_state(BATCH, column=column)
  stepped = []
  for step_inputs in inputs.unbind(1):
    step = network.step(step_inputs, state, column=column)
    stepped.append(step.action)
    state = step.state
  torch.testing.assert_close(torch.stack(stepped, dim=1), sequence, rtol=0, atol=1e-6)


def test_shared_input_gives_earlier_columns_its_leading_features() -> None:
  network = _exp1s_network(2)
  shared = torch.randn(BATCH, STEPS, network.input_size)
  per_column = [shared[..., : column.input_size] for column in network.columns]
  assert torch.equal(network(shared)[0], network(per_column)[0])


def test_shared_input_narrower_than_an_earlier_column_is_zero_padded_for_it() -> None:
  network = ProgressiveLSTM(hidden_size=8)
  network.add_column(10, 2)
  network.add_column(6, 2)
  shared = torch.randn(BATCH, STEPS, 6)
  padded = torch.cat([shared, torch.zeros(BATCH, STEPS, 4)], dim=-1)
  assert torch.equal(network(shared)[0], network([padded, shared])[0])


def test_state_of_the_wrong_number_of_columns_is_refused() -> None:
  network = _exp1s_network(3)
  with pytest.raises(ValueError, match="state holds 3 columns"):
    network.step(
      torch.randn(BATCH, network.columns[1].input_size),
      network.initial_state(BATCH),
      column=1,
    )


def test_rebuilding_from_config_gives_the_same_architecture() -> None:
  network = _exp1s_network(3)
  rebuilt = ProgressiveLSTM.from_config(network.config)
  assert (
    rebuilt.config == network.config == ProgressiveLSTMConfig(8, 2, ((14, 2), (16, 4), (18, 6)))
  )
  rebuilt.load_state_dict(network.state_dict())
  inputs = torch.randn(BATCH, STEPS, network.input_size)
  assert torch.equal(rebuilt(inputs)[0], network(inputs)[0])
  assert [parameter.requires_grad for parameter in rebuilt.parameters()] == [
    parameter.requires_grad for parameter in network.parameters()
  ]


def test_network_without_columns_says_how_to_start() -> None:
  with pytest.raises(ValueError, match="add_column"):
    ProgressiveLSTM().initial_state(1)
