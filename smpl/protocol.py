"""Data-agnostic steps of the continual-learning protocols (Exp1S, Exp2S, Exp2R).

A `ColumnTask` is what one column learns: a configuration of the arm in Exp1S, one module of a
fixed arm in Exp2S/Exp2R. Training a progressive network on a sequence of tasks adds and trains
one column per task; after each stage every column so far is scored on its own task, which gives
the forgetting matrix (rows: stages, columns: tasks). By construction its columns are constant
below the diagonal: later stages leave earlier columns' outputs bit-identical.
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Sequence
import contextlib
import dataclasses
from dataclasses import dataclass
import math

import torch
from torch import Tensor
from torch import nn

from smpl.fitting import CPU_THREADS
from smpl.fitting import EpochReport
from smpl.fitting import TrainingResult
from smpl.fitting import limited_cpu_threads
from smpl.fitting import seeded
from smpl.forward_model import ForwardModel
from smpl.progressive import ProgressiveLSTM
from smpl.rollout import rollout
from smpl.training import InverseTrainingConfig
from smpl.training import train_inverse_model
from smpl.windows import BabblingWindows
from smpl.windows import inverse_input_size


@dataclass(frozen=True)
class ColumnTask:
  """The data and frozen forward model of one configuration (Exp1S) or module (Exp2S/Exp2R)."""

  train: BabblingWindows
  validation: BabblingWindows
  test: BabblingWindows
  forward_model: ForwardModel


@dataclass(frozen=True)
class ColumnScore:
  """Closed-loop scores of one column on one set of windows, in normalised units."""

  action_mse: float
  """Mean squared difference between predicted and babbling actions."""
  pose_mse: float
  """Mean squared difference between the forward model's predicted poses and the targets."""


@dataclass
class ProgressiveRun:
  """Training results and scores of every stage of `train_progressively`."""

  training: list[TrainingResult]
  scores: list[list[ColumnScore]]
  """scores[stage][task] for tasks 0 .. stage."""

  def forgetting_matrix(self, metric: str = "pose_mse") -> Tensor:
    """(stages, tasks) of one ColumnScore field; NaN for tasks not yet seen at a stage."""
    if metric not in {field.name for field in dataclasses.fields(ColumnScore)}:
      raise ValueError(f"unknown metric {metric!r}")
    stages = len(self.scores)
    matrix = torch.full((stages, stages), math.nan, dtype=torch.float64)
    for stage, row in enumerate(self.scores):
      for task, score in enumerate(row):
        matrix[stage, task] = getattr(score, metric)
    return matrix


def train_next_column(
  network: ProgressiveLSTM,
  task: ColumnTask,
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[EpochReport], None] | None = None,
) -> TrainingResult:
  """Adds a column sized for `task` (freezing the earlier ones) and trains it in the loop.

  The new column's initial weights come from `config.seed` and the column's index.
  """
  windows = task.train
  with seeded(config.seed + network.num_columns, torch.device("cpu")):
    network.add_column(
      inverse_input_size(windows.pose_size, windows.action_size), windows.action_size
    )
  return train_inverse_model(
    network, task.forward_model, task.train, task.validation, config, device, on_epoch_end
  )


def evaluate_column(
  network: ProgressiveLSTM,
  column: int,
  windows: BabblingWindows,
  forward_model: ForwardModel,
  feed_back_error: bool = True,
) -> ColumnScore:
  """Scores column `column` alone (as with the later modules detached) on `windows`."""
  device = next(network.parameters()).device
  model = network.column_model(column).eval()
  windows = windows.to(device)
  with torch.no_grad(), limited_cpu_threads(CPU_THREADS, device):
    result = rollout(model, windows, forward_model.to(device), feed_back_error)
  return ColumnScore(
    action_mse=nn.functional.mse_loss(result.actions, windows.actions).item(),
    pose_mse=nn.functional.mse_loss(result.predicted_poses, windows.next_poses).item(),
  )


def evaluate_columns(
  network: ProgressiveLSTM, evaluations: Sequence[tuple[int, ColumnTask]]
) -> list[ColumnScore]:
  """Scores each (column, task) pair on the task's test windows: a forgetting-matrix row."""
  return [
    evaluate_column(network, column, task.test, task.forward_model) for column, task in evaluations
  ]


EpochCallback = Callable[[EpochReport], None]
StageProgress = Callable[[int], contextlib.AbstractContextManager[EpochCallback | None]]
"""Given a stage, a context entered around that stage's training that yields the callback its
epochs report to (a progress bar), or None."""


def no_progress(key: object) -> contextlib.AbstractContextManager[None]:
  """A progress factory (a ``StageProgress``, or any keyed one) that shows nothing."""
  return contextlib.nullcontext(None)


def train_progressively(
  network: ProgressiveLSTM,
  tasks: Sequence[ColumnTask],
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  stage_progress: StageProgress = no_progress,
) -> ProgressiveRun:
  """Trains one new column per task in order, scoring all columns so far after each stage."""
  first_new_column = network.num_columns
  run = ProgressiveRun(training=[], scores=[])
  for stage, task in enumerate(tasks):
    with stage_progress(stage) as on_epoch_end:
      run.training.append(train_next_column(network, task, config, device, on_epoch_end))
    seen = list(enumerate(tasks[: stage + 1], start=first_new_column))
    run.scores.append(evaluate_columns(network, seen))
  return run
