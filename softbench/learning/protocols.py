"""The paper's SMPL protocols on softbench's babbling data (SPEC section 5).

- ``exp1s`` (continual): tendon-1 .. tendon-5 in sequence, one new column per configuration,
  each learning the end effector's pose from every action of that configuration;
- ``exp2s`` (distributed, tendon-3) and ``exp2r`` (distributed, pneumatic-433): one column per
  module, each learning its module's pose and actions, with a forward model of its own that also
  reads the preceding modules' actuation.

Every column has its own dataset view, normalisation (fitted on its training split) and frozen
forward model. Columns are added and trained in order, and after each stage every column seen so
far is scored on its test windows, which gives the forgetting matrix. In Exp1S each column learns
alone (``smpl.protocol.train_progressively``); in Exp2S/Exp2R the columns act together, column k
on module k's own inputs (``smpl.training.train_column_jointly``), as the ``smpl`` agent does.
"""

from collections.abc import Callable
import contextlib
import dataclasses

import torch

from smpl import fitting
from smpl import forward_model as smpl_forward
from smpl import progressive
from smpl import protocol as smpl_protocol
from smpl import rollout as smpl_rollout
from smpl import training
from smpl import windows as smpl_windows
from softbench import data
from softbench import robots


@dataclasses.dataclass(frozen=True)
class Protocol:
  """A sequence of columns: one per robot (``per_module=False``) or per module of one robot."""

  name: str
  robot_names: tuple[str, ...]
  per_module: bool
  description: str

  def on_family(self, family: str) -> "Protocol":
    """The same protocol on the arms of tendon family ``family`` with the same module counts
    (``exp1s`` on tendon-local-1 .. tendon-local-5)."""
    names = tuple(f"{family}-{robots.make(name).num_modules}" for name in self.robot_names)
    if names == self.robot_names:
      return self
    return dataclasses.replace(
      self, robot_names=names, description=f"{self.description}, on the {family} family"
    )

  def column_views(self) -> list[tuple[robots.SoftArm, data.View]]:
    """The robot and data view of each column, in training order."""
    arms = [robots.make(name) for name in self.robot_names]
    if self.per_module:
      return [
        (arm, data.View.module(arm, module))
        for arm in arms
        for module in range(1, arm.num_modules + 1)
      ]
    return [(arm, data.View.end_effector(arm)) for arm in arms]


PROTOCOLS = {
  "exp1s": Protocol(
    "exp1s",
    tuple(f"tendon-{n}" for n in range(1, 6)),
    False,
    "continual: a new column for each of tendon-1 .. tendon-5",
  ),
  "exp2s": Protocol("exp2s", ("tendon-3",), True, "distributed: a column per module of tendon-3"),
  "exp2r": Protocol(
    "exp2r", ("pneumatic-433",), True, "distributed: a column per module of pneumatic-433"
  ),
}


def get(name: str) -> Protocol:
  if name not in PROTOCOLS:
    raise ValueError(f"unknown protocol {name!r}; choose one of {', '.join(PROTOCOLS)}")
  return PROTOCOLS[name]


@dataclasses.dataclass(frozen=True, eq=False)
class PreparedColumn:
  """What one column learns from: the robot, its windows (with normalisation) and a frozen
  forward model trained on them."""

  robot: robots.SoftArm
  windows: data.SplitWindows
  forward_model: smpl_forward.ForwardModel
  forward_training: fitting.TrainingResult

  @property
  def task(self) -> smpl_protocol.ColumnTask:
    return smpl_protocol.ColumnTask(
      self.windows.train, self.windows.validation, self.windows.test, self.forward_model
    )


def prepare_column(
  robot: robots.SoftArm,
  view: data.View,
  dataset: data.Dataset,
  config: training.ForwardTrainingConfig = training.ForwardTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[fitting.EpochReport], None] | None = None,
) -> PreparedColumn:
  """Cuts ``view``'s windows from ``dataset`` and trains (then freezes) its forward model."""
  windows = data.windows(dataset, view)
  with fitting.seeded(config.seed, torch.device("cpu")):
    model = smpl_forward.ForwardModel(windows.train.actuation_size, windows.train.pose_size)
  result = training.train_forward_model(
    model, windows.train, windows.validation, config, device, on_epoch_end
  )
  return PreparedColumn(robot, windows, model, result)


@dataclasses.dataclass(frozen=True, eq=False)
class ProtocolResult:
  protocol: Protocol
  network: progressive.ProgressiveLSTM
  columns: list[PreparedColumn]
  run: smpl_protocol.ProgressiveRun


ProgressBars = Callable[
  [str], contextlib.AbstractContextManager[smpl_protocol.EpochCallback | None]
]
"""Given a label (``forward tendon-2 end-effector``), a context entered around that model's
training that yields the callback its epochs report to (a progress bar), or None."""


def run(
  protocol: Protocol,
  samples: int = data.DEFAULT_SAMPLES,
  seed: int = 0,
  forward_config: training.ForwardTrainingConfig = training.ForwardTrainingConfig(),
  inverse_config: training.InverseTrainingConfig = training.InverseTrainingConfig(),
  device: torch.device | None = None,
  progress: bool = True,
  progress_bars: ProgressBars = smpl_protocol.no_progress,
) -> ProtocolResult:
  """Collects (or finds) each robot's dataset (babbling seed ``seed``), prepares every column,
  then trains the progressive network column by column (``smpl.protocol.train_progressively``,
  or all columns acting together for a per-module protocol). The configs' seeds fix the weights.
  """
  column_views = protocol.column_views()
  labels = [f"{arm.name} {view.name}" for arm, view in column_views]
  datasets, columns = {}, []
  for (arm, view), label in zip(column_views, labels):
    if arm.name not in datasets:
      datasets[arm.name] = data.collect(arm, samples=samples, seed=seed, progress=progress)
    with progress_bars(f"forward {label}") as on_epoch_end:
      columns.append(
        prepare_column(arm, view, datasets[arm.name], forward_config, device, on_epoch_end)
      )
  stage_bars = lambda stage: progress_bars(f"inverse {labels[stage]}")
  network = progressive.ProgressiveLSTM()
  if protocol.per_module:
    outcome = _train_jointly(network, columns, inverse_config, device, stage_bars)
  else:
    outcome = smpl_protocol.train_progressively(
      network, [column.task for column in columns], inverse_config, device, stage_bars
    )
  return ProtocolResult(protocol, network, columns, outcome)


def _train_jointly(
  network: progressive.ProgressiveLSTM,
  columns: list[PreparedColumn],
  config: training.InverseTrainingConfig,
  device: torch.device | None,
  stage_progress: smpl_protocol.StageProgress,
) -> smpl_protocol.ProgressiveRun:
  """Adds and trains one column per module, all columns acting together; scores after each."""
  device = device if device is not None else fitting.default_device()
  outcome = smpl_protocol.ProgressiveRun(training=[], scores=[])
  for stage, column in enumerate(columns):
    seen = columns[: stage + 1]
    split = lambda name: smpl_windows.ModuleWindows(tuple(getattr(c.windows, name) for c in seen))
    train = column.windows.train
    with fitting.seeded(config.seed + network.num_columns, torch.device("cpu")):
      network.add_column(
        smpl_windows.inverse_input_size(train.pose_size, train.action_size), train.action_size
      )
    forwards = [c.forward_model for c in seen]
    with stage_progress(stage) as on_epoch_end:
      outcome.training.append(
        training.train_column_jointly(
          network, forwards, split("train"), split("validation"), config, device, on_epoch_end
        )
      )
    test = split("test")  # Scored on the CPU, where the trained models are (fitting.on_device).
    with torch.no_grad(), fitting.limited_cpu_threads(config.cpu_threads, torch.device("cpu")):
      rollouts = smpl_rollout.joint_rollout(network.eval(), test, forwards)
    outcome.scores.append(
      [
        smpl_protocol.ColumnScore(
          torch.nn.functional.mse_loss(result.actions, windows.actions).item(),
          torch.nn.functional.mse_loss(result.predicted_poses, windows.next_poses).item(),
        )
        for result, windows in zip(rollouts, test.modules)
      ]
    )
  return outcome
