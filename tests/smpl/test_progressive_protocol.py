from collections.abc import Callable
import math

import pytest
import torch

from smpl.forward_model import ForwardModel
from smpl.progressive import ProgressiveLSTM
from smpl.protocol import ColumnTask
from smpl.protocol import ProgressiveRun
from smpl.protocol import evaluate_column
from smpl.protocol import train_progressively
from smpl.training import ForwardTrainingConfig
from smpl.training import InverseTrainingConfig
from smpl.training import train_forward_model
from smpl.windows import BabblingWindows

CPU = torch.device("cpu")


def _configuration_task(
  make_arm_windows: Callable[..., BabblingWindows], module_count: int
) -> ColumnTask:
  """An Exp1S-like stage: an arm of `module_count` two-input modules and its forward model."""
  action_size = 2 * module_count

  def windows(steps: int, seed: int) -> BabblingWindows:
    return make_arm_windows(steps, action_size, seed=seed, arm_seed=module_count)

  seed = 10 * module_count
  train, validation, test = windows(150, seed), windows(60, seed + 1), windows(60, seed + 2)
  torch.manual_seed(module_count)
  forward_model = ForwardModel(action_size, hidden_size=16)
  train_forward_model(forward_model, train, validation, ForwardTrainingConfig(max_epochs=5), CPU)
  return ColumnTask(train, validation, test, forward_model)


@pytest.fixture(scope="module")
def two_stage_run(
  make_arm_windows: Callable[..., BabblingWindows],
) -> tuple[ProgressiveLSTM, list[ColumnTask], ProgressiveRun]:
  tasks = [_configuration_task(make_arm_windows, modules) for modules in (1, 2)]
  network = ProgressiveLSTM(hidden_size=16)
  run = train_progressively(network, tasks, InverseTrainingConfig(max_epochs=2), CPU)
  return network, tasks, run


def test_each_stage_adds_one_column_sized_for_its_configuration(two_stage_run) -> None:
  network, _, run = two_stage_run
  assert network.config.column_sizes == ((14, 2), (16, 4))
  assert len(run.training) == 2 and all(result.epochs_run == 2 for result in run.training)
  assert not any(parameter.requires_grad for parameter in network.columns[0].parameters())


def test_earlier_configurations_score_exactly_the_same_after_later_stages(two_stage_run) -> None:
  _, _, run = two_stage_run
  assert [len(row) for row in run.scores] == [1, 2]
  assert run.scores[1][0] == run.scores[0][0]


def test_forgetting_matrix_has_a_row_per_stage_and_nothing_above_the_diagonal(
  two_stage_run,
) -> None:
  _, _, run = two_stage_run
  matrix = run.forgetting_matrix("action_mse")
  assert matrix.shape == (2, 2)
  assert math.isnan(matrix[0, 1])
  assert matrix[0, 0] == matrix[1, 0] == run.scores[0][0].action_mse
  assert matrix[1, 1] == run.scores[1][1].action_mse
  with pytest.raises(ValueError, match="unknown metric"):
    run.forgetting_matrix("accuracy")


def test_open_loop_scoring_differs_from_closed_loop(two_stage_run) -> None:
  network, tasks, _ = two_stage_run
  task = tasks[1]
  closed = evaluate_column(network, 1, task.test, task.forward_model)
  opened = evaluate_column(network, 1, task.test, task.forward_model, feed_back_error=False)
  assert closed != opened
