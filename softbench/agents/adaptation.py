"""Adapting a trained SMPL agent to an actuator fault by retraining the faulty module's column.

``retrain_column(agent, faulty_robot, seed, profile)`` takes the ``smpl`` agent trained on the
healthy robot and a robot whose faults (``softbench.robots.faults``) all lie in one module M, and
returns an agent whose column M is retrained on new motor babbling of the faulty robot (the
profile's sample count, data seed ``inverse_training.DATA_SEED``), with every other column's
parameters bit-identical to the healthy agent's. What it retrains, and why:

- Forward models of modules M..N (N the last module): they read module M's actuation, and the
  fault changes where that actuation takes module M's tip and every tip beyond it. The forward
  models of modules 1..M-1 are kept: they never read module M's actuation (a distal cable's pull
  on proximal modules was already a disturbance they could not attribute), and they only feed
  the error inputs of the frozen columns 1..M-1.
- Column M: all columns act together (``smpl.rollout.joint_rollout``) and column M is trained on
  the mean action MSE of modules M..N. Columns M+1..N read column M's hidden states through
  their lateral connections, so its new features must keep serving them; they stay frozen.

Both the forward models and column M start from their healthy weights (adaptation, not learning
from scratch) and train with the profile's epoch budget and early stopping. Every controller
keeps the normalisation it was trained with, so the frozen columns see inputs scaled as before.

The retrained weights are cached under ``$SOFTBENCH_HOME/checkpoints`` by a ``RetrainedConfig``
that names the healthy checkpoint and the faults, with the wall time of the retraining beside it
(``<checkpoint>.timing.json``).
"""

import copy
import dataclasses
import json
import pathlib
import time

import torch

from smpl import checkpoint
from smpl import fitting
from smpl import progressive
from smpl import training
from smpl import windows as smpl_windows
from softbench import data
from softbench import profiles
from softbench import progress as progress_bars
from softbench import storage
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training
from softbench.robots import base as robot_base

ADAPTATION_VERSION = 1  # Bump when retraining changes, so cached retrained columns are not reused.
TIMING_SUFFIX = ".timing.json"


@dataclasses.dataclass(frozen=True)
class RetrainedConfig:
  """Everything a retrained column's weights depend on; its hash names the checkpoint."""

  healthy_checkpoint: str  # Key of the healthy agent's checkpoint (its TrainedConfig).
  faults: tuple[tuple[int, int, float], ...]  # (module, actuator, gain), sorted.
  faulty_robot_xml_sha256: str
  column: int  # The retrained module, from 1.
  retrained_forward_modules: tuple[int, ...]
  samples: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  adaptation_version: int = ADAPTATION_VERSION

  @property
  def key(self) -> str:
    faults = "-".join(f"{module}.{actuator}.{gain:g}" for module, actuator, gain in self.faults)
    return storage.config_key(
      self,
      f"{self.healthy_checkpoint.split('-seed')[0]}-fault{faults}-column{self.column}-"
      f"seed{self.seed}",
    )


@dataclasses.dataclass(frozen=True, eq=False)
class RetrainedColumn:
  """The adapted agent and what it took.

  Attributes:
    agent: The SMPL agent with column ``column`` (and forward models) retrained.
    column: The retrained module, from 1.
    retrained_forward_modules: Modules whose forward models were retrained.
    wall_time_s: Seconds the retraining took (forward models and column, not the babbling), when
      it was timed: now, or when the cached checkpoint was made.
    trained_now: False if the retrained weights came from the cache.
  """

  agent: learned.LearnedAgent
  column: int
  retrained_forward_modules: tuple[int, ...]
  wall_time_s: float | None
  trained_now: bool


def faulty_module(robot: robot_base.SoftArm) -> int:
  """The one module that holds every fault of ``robot``; a one-line ValueError otherwise."""
  modules = sorted({fault.module for fault in robot.faults})
  if len(modules) != 1:
    raise ValueError(
      "retraining one column needs faults in exactly one module, got "
      + (f"modules {', '.join(map(str, modules))}" if modules else "no fault")
    )
  return modules[0]


def read_wall_time(path: pathlib.Path) -> float | None:
  """The training wall time recorded beside checkpoint ``path``, or None."""
  try:
    return float(json.loads(path.with_name(path.name + TIMING_SUFFIX).read_text())["wall_time_s"])
  except (OSError, ValueError, KeyError, TypeError):
    return None


def write_wall_time(path: pathlib.Path, seconds: float) -> None:
  storage.write_atomically(
    path.with_name(path.name + TIMING_SUFFIX), json.dumps({"wall_time_s": seconds}) + "\n"
  )


def retrain_column(
  agent: learned.LearnedAgent,
  faulty_robot: robot_base.SoftArm,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> RetrainedColumn:
  """``agent`` (the smpl agent built for the healthy robot with ``profile``) with the faulty
  module's column retrained, from the cache or trained now and then cached (module docstring);
  the retraining is seeded by the agent's seed.

  Raises:
    ValueError: the agent is not a progressive (smpl) agent, or the faults are not all in one
      module (one line).
  """
  if not isinstance(agent.inverse, progressive.ProgressiveLSTM):
    raise ValueError("only the smpl agent (one column per module) retrains a single column")
  module, seed = faulty_module(faulty_robot), agent.seed
  forward_modules = tuple(range(module, faulty_robot.num_modules + 1))
  healthy = faulty_robot.without_faults()
  config = RetrainedConfig(
    learned.checkpoint_path("smpl", healthy, seed, profile, per_module=True).stem,
    tuple(sorted((f.module, f.actuator, f.gain) for f in faulty_robot.faults)),
    faulty_robot.physics_sha256(),
    module,
    forward_modules,
    seed=seed,
    **profile.training(),
  )
  path = checkpoints.checkpoint_file(config)
  inverse = copy.deepcopy(agent.inverse)
  forwards = [copy.deepcopy(controller.forward).freeze() for controller in agent.controllers]
  bundle = torch.nn.ModuleDict(
    {"inverse": inverse, "forward_models": torch.nn.ModuleList(forwards)}
  )
  # A damaged cached file is reported (storage.read_cached) and trained again; a refused file
  # leaves the bundle untouched, so the retraining starts from the healthy weights.
  trained_now = (
    storage.read_cached(
      path,
      lambda found: checkpoint.load_checkpoint(found, bundle, config),
      "retrained column",
      "training it again",
    )
    is None
  )
  if trained_now:
    dataset = data.collect(
      faulty_robot, samples=profile.samples, seed=inverse_training.DATA_SEED, progress=show_progress
    )
    started = time.perf_counter()
    _retrain(agent, inverse, forwards, dataset, module, seed, profile, show_progress)
    wall_time = round(time.perf_counter() - started, 3)
    checkpoint.save_checkpoint(path, bundle, config)
    write_wall_time(path, wall_time)
  else:
    wall_time = read_wall_time(path)
  inverse.cpu().requires_grad_(False).eval()
  controllers = [
    learned.Controller(controller.view, forward.cpu().eval(), controller.normalisation)
    for controller, forward in zip(agent.controllers, forwards)
  ]
  adapted = learned.LearnedAgent(
    faulty_robot, seed, inverse, controllers, agent.acting, agent.candidates
  )
  return RetrainedColumn(adapted, module, forward_modules, wall_time, trained_now)


def _retrain(
  agent: learned.LearnedAgent,
  inverse: progressive.ProgressiveLSTM,
  forwards: list,
  dataset: data.Dataset,
  module: int,
  seed: int,
  profile: profiles.Profile,
  show: bool,
) -> None:
  """Retrains, in place on ``dataset`` (the faulty robot's babbling), forward models module..N
  and column ``module`` of ``inverse``."""
  windows = [
    data.windows(dataset, controller.view, fitted=controller.normalisation)
    for controller in agent.controllers
  ]
  forward_config, inverse_config = inverse_training.training_configs(
    seed, profile, hyperparameters.values("smpl", agent.robot.name)
  )
  device = fitting.default_device()
  label = f"{dataset.robot_name} seed {seed}"
  for index in range(module - 1, len(forwards)):
    forwards[index].requires_grad_(True)
    bar_label = f"forward module-{index + 1} {label}"
    with progress_bars.epochs(bar_label, profile.max_epochs, show) as bar:
      training.train_forward_model(
        forwards[index],
        windows[index].train,
        windows[index].validation,
        forward_config,
        device,
        bar,
      )
  inverse.requires_grad_(False)
  inverse.columns[module - 1].requires_grad_(True)
  split = lambda name: smpl_windows.ModuleWindows(tuple(getattr(w, name) for w in windows))
  with progress_bars.epochs(f"inverse column {module} {label}", profile.max_epochs, show) as bar:
    training.train_column_jointly(
      inverse,
      forwards,
      split("train"),
      split("validation"),
      inverse_config,
      device,
      bar,
      column=module - 1,
    )
  inverse.requires_grad_(False)


def columns_bit_identical(
  before: progressive.ProgressiveLSTM, after: progressive.ProgressiveLSTM, skip: int
) -> bool:
  """Whether every column but ``skip`` (a module, from 1) has bit-identical parameters."""
  return all(
    all(
      torch.equal(tensor, after.columns[index].state_dict()[name].to(tensor.device))
      for name, tensor in column.state_dict().items()
    )
    for index, column in enumerate(before.columns)
    if index != skip - 1
  )
