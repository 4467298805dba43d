"""Distributed SMPL: every column acts on its own module's inputs in one joint closed loop."""

from __future__ import annotations

import pytest
import torch

from smpl.forward_model import ForwardModel
from smpl.progressive import ProgressiveLSTM
from smpl.rollout import joint_rollout
from smpl.rollout import rollout
from smpl.training import InverseTrainingConfig
from smpl.training import train_column_jointly
from smpl.windows import ModuleWindows
from smpl.windows import inverse_input_size

ACTIONS = (4, 3)  # Actions of module 1 and module 2 (as pneumatic-433's first two modules).


@pytest.fixture
def modules(make_arm_windows) -> ModuleWindows:
  return ModuleWindows(
    tuple(
      make_arm_windows(60, size, seed=index, arm_seed=index) for index, size in enumerate(ACTIONS)
    )
  )


def _network() -> ProgressiveLSTM:
  torch.manual_seed(0)
  network = ProgressiveLSTM(hidden_size=8)
  for size in ACTIONS:
    network.add_column(inverse_input_size(6, size), size)
  return network


def _forward_models() -> list[ForwardModel]:
  torch.manual_seed(1)
  return [ForwardModel(size, hidden_size=8).freeze() for size in ACTIONS]


def test_step_columns_gives_each_column_its_step_output() -> None:
  network = _network()
  inputs = [torch.randn(5, column.input_size) for column in network.columns]
  state = network.initial_state(5)
  actions, _ = network.step_columns(inputs, state)
  assert [action.shape for action in actions] == [(5, size) for size in ACTIONS]
  assert torch.equal(actions[0], network.step(inputs[0], network.initial_state(5, 0), 0).action)
  assert torch.equal(actions[1], network.step(inputs, state).action)


def test_first_module_rolls_out_as_its_column_alone(modules: ModuleWindows) -> None:
  """Column 0 reads no other column, so the joint loop gives it exactly its own rollout."""
  network, forwards = _network(), _forward_models()
  with torch.no_grad():
    joint = joint_rollout(network, modules, forwards)
    alone = rollout(network.column_model(0), modules.modules[0], forwards[0])
  assert torch.equal(joint[0].actions, alone.actions)
  assert torch.equal(joint[0].errors, alone.errors)
  assert torch.equal(joint[1].errors[:, 0], torch.zeros_like(joint[1].errors[:, 0]))


def test_distal_column_depends_on_the_proximal_module_targets(modules: ModuleWindows) -> None:
  network, forwards = _network(), _forward_models()
  changed = modules.modules[0].poses.clone()
  changed[:, 3:] += 0.5  # Module 1's later targets move; module 2's inputs stay the same.
  moved = ModuleWindows(
    (
      type(modules.modules[0])(
        changed, modules.modules[0].actions, modules.modules[0].preceding_actions
      ),
      modules.modules[1],
    )
  )
  with torch.no_grad():
    before = joint_rollout(network, modules, forwards)[1].actions
    after = joint_rollout(network, moved, forwards)[1].actions
  assert not torch.equal(before, after)


def test_training_a_column_jointly_leaves_the_earlier_one_bit_identical(modules) -> None:
  network, forwards = _network(), _forward_models()  # add_column froze column 0.
  before = {name: value.clone() for name, value in network.columns[0].state_dict().items()}
  untrained = [p.clone() for p in network.columns[1].parameters()]
  config = InverseTrainingConfig(max_epochs=2, patience=2)
  train_column_jointly(network, forwards, modules, modules, config, torch.device("cpu"))
  after = network.columns[0].state_dict()
  assert all(torch.equal(before[name], after[name]) for name in before)
  assert any(not torch.equal(a, b) for a, b in zip(untrained, network.columns[1].parameters()))


def test_joint_training_refuses_unfrozen_earlier_columns(modules) -> None:
  network = _network()
  network.columns[0].requires_grad_(True)
  with pytest.raises(ValueError, match="earlier columns must be frozen"):
    train_column_jointly(
      network,
      _forward_models(),
      modules,
      modules,
      InverseTrainingConfig(max_epochs=1),
      torch.device("cpu"),
    )


def test_retraining_an_earlier_column_leaves_the_later_one_bit_identical(modules) -> None:
  """Retraining column 0 (an actuator fault in module 1): the loss covers both modules, since
  column 1 reads column 0 laterally, and column 1's parameters stay bit-identical."""
  network, forwards = _network(), _forward_models()
  network.columns.requires_grad_(False)
  network.columns[0].requires_grad_(True)
  later = {name: value.clone() for name, value in network.columns[1].state_dict().items()}
  before = [p.clone() for p in network.columns[0].parameters()]
  config = InverseTrainingConfig(max_epochs=2, patience=2)
  train_column_jointly(network, forwards, modules, modules, config, torch.device("cpu"), column=0)
  after = network.columns[1].state_dict()
  assert all(torch.equal(later[name], after[name]) for name in later)
  assert any(not torch.equal(a, b) for a, b in zip(before, network.columns[0].parameters()))


def test_retraining_refuses_other_unfrozen_columns_and_a_missing_column(modules) -> None:
  network = _network()  # add_column left the last column trainable.
  network.columns[0].requires_grad_(True)
  with pytest.raises(ValueError, match="every column but 0 must be frozen"):
    train_column_jointly(
      network,
      _forward_models(),
      modules,
      modules,
      InverseTrainingConfig(max_epochs=1),
      torch.device("cpu"),
      column=0,
    )
  with pytest.raises(ValueError, match="column must be 0 to 1"):
    train_column_jointly(
      network,
      _forward_models(),
      modules,
      modules,
      InverseTrainingConfig(max_epochs=1),
      torch.device("cpu"),
      column=2,
    )


def test_module_windows_must_be_aligned(make_arm_windows) -> None:
  with pytest.raises(ValueError, match="not aligned"):
    ModuleWindows((make_arm_windows(60, 4, seed=0), make_arm_windows(50, 3, seed=1)))


@pytest.mark.parametrize("acted", [False, True])
def test_acted_preceding_feeds_module_2_the_proximal_column_s_actions(make_arm_windows, acted):
  """Module 2's forward model reads module 1's actuation: the recorded one by default, with
  acted_preceding the actions column 1 just took (then the recorded one is not read)."""
  first = make_arm_windows(60, ACTIONS[0], seed=0, arm_seed=0)
  second = make_arm_windows(60, ACTIONS[1], seed=1, arm_seed=1)
  network = _network()
  torch.manual_seed(1)
  forwards = [ForwardModel(size, hidden_size=8).freeze() for size in (ACTIONS[0], sum(ACTIONS))]

  def module_2_errors(preceding: torch.Tensor) -> torch.Tensor:
    windows = ModuleWindows((first, type(second)(second.poses, second.actions, preceding)))
    with torch.no_grad():
      return joint_rollout(network, windows, forwards, acted_preceding=acted)[1].errors

  recorded = module_2_errors(first.actions)
  assert torch.equal(recorded, module_2_errors(first.actions + 0.5)) == acted
