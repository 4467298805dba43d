"""The SMPL protocols wired to real babbling data, on tiny robots, datasets and budgets."""

import contextlib

import numpy as np
import pytest
import torch

from smpl import training
from softbench.learning import protocols

SAMPLES = 200  # Enough for a 15-step window in every split (validation: 20 samples).
TINY_FORWARD = training.ForwardTrainingConfig(max_epochs=2, patience=2)
TINY_INVERSE = training.InverseTrainingConfig(max_epochs=2, patience=2)


@pytest.fixture(autouse=True)
def data_home(tmp_path_factory, babbled_home):
  """One data home for the file, holding the tiny datasets of the robots its protocols learn."""
  for robot in ("tendon-1", "tendon-2", "pneumatic-433"):
    babbled_home(tmp_path_factory.getbasetemp() / "protocols_home", robot)


def test_the_paper_protocols_have_the_papers_columns():
  names = lambda protocol: [view.name for _, view in protocol.column_views()]
  exp1s = protocols.get("exp1s")
  assert [arm.name for arm, _ in exp1s.column_views()] == [f"tendon-{n}" for n in range(1, 6)]
  assert set(names(exp1s)) == {"end-effector"}
  assert names(protocols.get("exp2s")) == ["module-1", "module-2", "module-3"]
  exp2r_actions = [view.action_size for _, view in protocols.get("exp2r").column_views()]
  assert exp2r_actions == [4, 3, 3]
  with pytest.raises(ValueError, match="unknown protocol"):
    protocols.get("exp3")


@pytest.mark.parametrize(
  "protocol",
  [
    protocols.Protocol("continual", ("tendon-1", "tendon-2"), False, "Exp1S in small"),
    protocols.Protocol("distributed", ("pneumatic-433",), True, "Exp2R: modules of 4, 3, 3"),
  ],
)
def test_protocol_trains_a_column_per_stage_and_never_forgets(protocol):
  result = protocols.run(
    protocol,
    samples=SAMPLES,
    forward_config=TINY_FORWARD,
    inverse_config=TINY_INVERSE,
    device=torch.device("cpu"),
    progress=False,
  )
  stages = len(protocol.column_views())
  assert result.network.num_columns == stages
  assert all(column.forward_model.is_frozen for column in result.columns)
  matrix = result.run.forgetting_matrix("action_mse").numpy()
  assert matrix.shape == (stages, stages)
  assert np.all(np.isnan(matrix[np.triu_indices(stages, 1)]))
  assert np.all(np.isfinite(matrix[np.tril_indices(stages)]))
  # Later stages leave every earlier column's score bit-identical.
  for task in range(stages):
    assert len(set(matrix[task:, task].tolist())) == 1
  for index, (column, (arm, view)) in enumerate(zip(result.columns, protocol.column_views())):
    assert result.network.columns[index].output_size == view.action_size
    assert column.windows.train.pose_size == view.pose_size


def test_protocol_reports_every_epoch_of_every_model_to_its_progress_bar():
  protocol = protocols.Protocol("continual", ("tendon-1", "tendon-2"), False, "Exp1S in small")
  epochs = {}

  @contextlib.contextmanager
  def progress_bars(label):
    epochs[label] = []
    yield lambda report: epochs[label].append(report.epoch)

  result = protocols.run(
    protocol,
    samples=SAMPLES,
    forward_config=TINY_FORWARD,
    inverse_config=TINY_INVERSE,
    device=torch.device("cpu"),
    progress=False,
    progress_bars=progress_bars,
  )
  assert list(epochs) == [
    "forward tendon-1 end-effector",
    "forward tendon-2 end-effector",
    "inverse tendon-1 end-effector",
    "inverse tendon-2 end-effector",
  ]
  trained = [column.forward_training for column in result.columns] + result.run.training
  for label, training_result in zip(epochs, trained):
    assert epochs[label] == [report.epoch for report in training_result.history], label
