"""A strategy learning a stream, stage by stage, for one seed: cached after every stage.

Each configuration's data is its babbling dataset in the end effector's view, with its frozen
forward model (``learning.inverse.trained_forward_models``: the cache every agent reading that
view with that seed shares). Stage s: the strategy grows, learns (timed), and is scored at model
level: every configuration seen so far, closed loop through its forward model on its test
windows (pose and action MSE, normalised units). Its state after the stage (``Strategy.module``)
and the stage's summary are cached under ``$SOFTBENCH_HOME/continual/<key>/stage<s>.pt``, keyed
by everything they depend on (``StreamConfig``), so an interrupted run resumes at the first stage
it had not finished (a stage itself resumes from its epoch snapshots, ``smpl.snapshots``).
"""

from collections.abc import Iterator
import dataclasses
import io
import pathlib
import time

import torch

from smpl import fitting
from smpl import rollout as smpl_rollout
from smpl import snapshots
from softbench import data
from softbench import profiles
from softbench import progress as progress_bars
from softbench import storage
from softbench.agents import hyperparameters
from softbench.continual import strategies
from softbench.continual import streams
from softbench.continual.strategies import base as strategy_base
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training

FOLDER = "continual"  # Under the data home.
VERSION = 1  # Of the strategies' training: a change that alters weights increments it.
HYPERPARAMETER_AGENT = "smpl"  # Every strategy trains with SMPL's committed optimiser settings.


@dataclasses.dataclass(frozen=True)
class StreamConfig:
  """Everything a seed's stage states depend on; its hash names their folder."""

  strategy: str
  stream: str
  configurations: tuple[str, ...]  # physics_sha256 of each configuration's robot.
  seed: int
  samples: int
  max_epochs: int
  patience: int
  compile: bool
  params: tuple[tuple[str, object], ...]
  constants: tuple[tuple[str, object], ...]  # The strategy's own (``Strategy.constants``).
  training_version: int = checkpoints.TRAINING_VERSION
  version: int = VERSION

  @property
  def key(self) -> str:
    return storage.config_key(self, f"{self.strategy}-{self.stream}-seed{self.seed}")


def params(configurations: tuple[streams.Configuration, ...]) -> dict:
  """The optimiser settings of every strategy: SMPL's, for the stream's largest robot (its own
  committed values, else those tuned on tendon-3)."""
  largest = max(configurations, key=lambda configuration: configuration.robot.action_dim)
  return hyperparameters.values(HYPERPARAMETER_AGENT, largest.robot.name)


def config(
  strategy: str,
  stream: str,
  configurations: tuple[streams.Configuration, ...],
  seed: int,
  profile: profiles.Profile,
) -> StreamConfig:
  return StreamConfig(
    strategy,
    stream,
    tuple(configuration.robot.physics_sha256() for configuration in configurations),
    seed,
    params=tuple(sorted(params(configurations).items())),
    constants=tuple(sorted(strategies.strategy_class(strategy).constants().items())),
    **profile.training(),
  )


def folder(named: StreamConfig) -> pathlib.Path:
  """Where the stage states of ``named`` are cached."""
  return storage.softbench_home() / FOLDER / named.key


def stage_path(cache: pathlib.Path, stage: int) -> pathlib.Path:
  """Where the state after stage ``stage`` is cached in ``cache`` (a ``folder``)."""
  return cache / f"stage{stage}.pt"


def stage_data(
  configurations: tuple[streams.Configuration, ...],
  seed: int,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> list[strategy_base.StageData]:
  """Every configuration's windows and frozen forward model (collected, trained or found)."""
  stages = []
  for configuration in configurations:
    robot = configuration.robot
    (windows,), (forward,) = inverse_training.trained_forward_models(
      robot, [data.View.end_effector(robot)], seed, profile, show_progress
    )
    stages.append(strategy_base.StageData(configuration, windows, forward))
  return stages


def setting(
  stages: list[strategy_base.StageData], seed: int, profile: profiles.Profile
) -> strategy_base.Setting:
  """The ``Setting`` of a run on ``stages``."""
  _, inverse_config = inverse_training.training_configs(
    seed, profile, params(tuple(stage.configuration for stage in stages))
  )
  pose_sizes = {stage.pose_size for stage in stages}
  if len(pose_sizes) != 1:
    raise ValueError(f"a stream's configurations must share a pose size, got {sorted(pose_sizes)}")
  return strategy_base.Setting(
    pose_sizes.pop(),
    tuple(stage.action_size for stage in stages),
    inverse_config,
    fitting.default_device(),
  )


def model_scores(
  strategy: strategy_base.Strategy, stages: list[strategy_base.StageData], upto: int
) -> dict:
  """Pose and action MSE (normalised) of configurations 0..``upto`` on their test windows, closed
  loop through their forward models."""
  scores = {"model_pose_mse": [], "model_action_mse": []}
  with torch.no_grad(), fitting.limited_cpu_threads(fitting.CPU_THREADS, torch.device("cpu")):
    for configuration in range(upto + 1):
      test = stages[configuration].windows.test
      result = smpl_rollout.rollout(
        strategy.controller(configuration), test, stages[configuration].forward, True
      )
      scores["model_pose_mse"].append(
        torch.nn.functional.mse_loss(result.predicted_poses, test.next_poses).item()
      )
      scores["model_action_mse"].append(
        torch.nn.functional.mse_loss(result.actions, test.actions).item()
      )
  return scores


def _values(module: torch.nn.Module) -> dict[str, torch.Tensor]:
  return {name: tensor.detach().clone() for name, tensor in module.state_dict().items()}


def _summary(
  strategy: strategy_base.Strategy,
  stage: int,
  stages: list[strategy_base.StageData],
  trained: strategy_base.StageTraining,
  before: dict[str, torch.Tensor],
  seconds: float,
) -> dict:
  """What a record keeps of one stage (``learn``'s docstring)."""
  parameters = dict(strategy.module.named_parameters())
  changed = sum(
    tensor.numel()
    for name, tensor in parameters.items()
    if name not in before or not torch.equal(before[name], tensor.detach())
  )
  state = strategy.module.state_dict()
  return {
    "stage": stage,
    "trained_on": list(trained.trained_on),
    "epochs": [result.epochs_run for result in trained.results],
    "best_validation_loss": [result.best_validation_loss for result in trained.results],
    "validation_curve": [
      [report.validation_loss for report in result.history] for result in trained.results
    ],
    "training_seconds": round(seconds, 3),
    "parameters": sum(tensor.numel() for tensor in parameters.values()),
    "parameters_trained": changed,
    "carried_values": sum(tensor.numel() for tensor in state.values()),
    **model_scores(strategy, stages, stage),
  }


def learn(
  strategy_name: str,
  stream: streams.Stream,
  family: str,
  seed: int,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> Iterator[tuple[strategy_base.Strategy, list[strategy_base.StageData], dict]]:
  """After each stage of ``stream`` (on ``family``) learned by ``strategy_name`` with ``seed``:
  the strategy, every stage's data, and the stage's summary: ``trained_on`` (configurations
  whose data it read), per fit ``epochs``, ``best_validation_loss`` and ``validation_curve``
  (each epoch's validation loss), ``training_seconds`` (the stage's learning, with the epochs a
  resumed training ran before it stopped), ``parameters`` (after the stage),
  ``parameters_trained`` (those the stage changed), ``carried_values`` (every number the
  strategy carries to the next stage: weights, Fisher information, buffers) and the model-level
  ``model_pose_mse`` and ``model_action_mse`` of configurations 0..s. From the cache where a
  stage was learned before."""
  configurations = stream.configurations(family)
  stages = stage_data(configurations, seed, profile, show_progress)
  strategies.strategy_class(strategy_name).check(configurations)
  strategy = strategies.make(strategy_name, setting(stages, seed, profile))
  cache = folder(config(strategy_name, stream.name, configurations, seed, profile))
  for stage in range(len(stages)):
    strategy.grow(stage)
    path = stage_path(cache, stage)
    summary = _cached(path, strategy)
    if summary is None:
      seen = stages[: stage + 1] if strategy.continual else stages
      label = f"{strategy_name} {stream.name} seed {seed}: {configurations[stage].label}"
      before = _values(strategy.module)
      started = time.perf_counter()
      with (
        snapshots.resumable(cache / f"stage{stage}.partial"),
        progress_bars.epochs(label, profile.max_epochs, show_progress) as bar,
      ):
        earlier = EarlierEpochs(bar)
        trained = strategy.learn(stage, seen, earlier)
      seconds = time.perf_counter() - started + earlier.seconds
      summary = _summary(strategy, stage, stages, trained, before, seconds)
      _save(path, strategy, summary)
      snapshots.discard(cache / f"stage{stage}.partial")
    yield strategy, stages, summary


class EarlierEpochs:
  """The epoch callback a stage's learning gets: adds up the seconds of the epochs a resumed
  training ran before it was stopped (``smpl.fitting`` hands them on again, marked ``resumed``),
  so that a stage's ``training_seconds`` counts them, then passes every report to ``forward``
  (a progress bar's callback, or None)."""

  def __init__(self, forward) -> None:
    self.forward = forward
    self.seconds = 0.0

  def __call__(self, report: fitting.EpochReport) -> None:
    if report.resumed:
      self.seconds += report.seconds
    if self.forward is not None:
      self.forward(report)


def _save(path: pathlib.Path, strategy: strategy_base.Strategy, summary: dict) -> None:
  buffer = io.BytesIO()
  torch.save({"state": strategy.module.state_dict(), "summary": summary}, buffer)
  path.parent.mkdir(parents=True, exist_ok=True)
  storage.write_atomically(path, buffer.getvalue())


def _cached(path: pathlib.Path, strategy: strategy_base.Strategy) -> dict | None:
  """The cached summary of a stage, its state loaded into ``strategy``; None if there is none
  (or it is damaged: reported once, and the stage learns again)."""

  def load(found: pathlib.Path) -> dict:
    saved = torch.load(found, map_location="cpu", weights_only=True)
    # The weights only: which parameters a later stage trains is the strategy's (SMPL's and
    # independent's earlier networks stay out of later trainings; a shared network trains on).
    strategy.module.load_state_dict(saved["state"])
    return saved["summary"]

  return storage.read_cached(path, load, "continual stage", "learning it again")
