"""Learned agents: inverse models trained on motor babbling in closed loop, then acting on a task.

Training (cached): the robot's babbling dataset (``softbench.data.collect``, data seed 0, the
profile's sample count), cut into each controller's view; a forward model per view (trained once
and shared by the agents that read the same view, ``forward_models``), then the inverse model in
closed loop through it (``smpl.training``), seeded by the agent's seed. SMPL has
one progressive column per module (``View.module``, trained in order, earlier columns frozen);
the baselines are one centralised model over the whole arm (``View.whole_arm``). Each agent
trains with its committed hyperparameters (``softbench.agents.hyperparameters``), which enter the
checkpoint's config, so a change of values never reuses a stale checkpoint. An interrupted training
resumes from its snapshots (``smpl.snapshots``, in ``snapshot_folder``) to the same weights.

Acting, at control step t, each controller reads (normalised with its training statistics)

    u_t = [x*_{t+1}, e_t, a_{t-1}],   e_t = x*_t - x_t   (physics: the measured pose x_t)

where x*_{t+1} is this step's target and x*_t the previous one; e_0 = 0 and a_{-1} = 0 (SPEC 5).
``error_source`` chooses e_t: ``physics`` (the headline), ``model`` (x_t replaced by the forward
model's prediction, the paper's protocol) or ``open-loop`` (e_t = 0).

A target that gives only part of the arm's pose (reach: one module's position; a masked custom
trajectory) is completed by ``helper_targets``: ``complete`` (default) and ``nearest`` complete
it from the agent's own babbling and forward models (``softbench.agents.completion``; corrected
from the measured error only with ``error_source`` ``physics``); ``hold`` holds every module not
given at its starting pose and keeps a given module's starting orientation if only its position
is given; ``share`` gives every active module the scored module's remaining position error, as
its pose now shifted by that error, and asks every inactive one for nothing (its pose now). A
target that gives every module's whole pose is used as it is.

``active_modules`` (1-based; None: every module) switches modules off: their action entries are zero
(passive: no cable tension, zero pressure). The model still computes every output, so an SMPL column
of an inactive module keeps running as an observer of its module, on its real pose, target, error
and the zero action it actually received; the active columns read it through the lateral connections
as they were trained to. A centralised baseline is masked the same way, which keeps comparisons fair
(``softbench.runners.adaptive``). With every module active the actions are those of the unmasked
agent, bit for bit.
"""

import dataclasses
import pathlib
from typing import Callable

import numpy as np
import torch

from smpl import checkpoint
from smpl import forward_model as smpl_forward
from smpl import progressive
from smpl import snapshots
from smpl import training
from smpl import windows as smpl_windows
from smpl.inverse import InverseModel
from softbench import data
from softbench import profiles
from softbench import progress as progress_bars
from softbench import storage
from softbench import zoo
from softbench.agents import base
from softbench.agents import completion
from softbench.agents import hyperparameters
from softbench.agents import learners
from softbench.learning import forward_models
from softbench.records.fields import ERROR_SOURCES
from softbench.records.fields import HELPER_TARGETS
from softbench.robots import base as robot_base
from softbench.robots import recorder
from softbench.suite import trajectories

DEFAULT_HELPER_TARGETS = "complete"
CHECKPOINT_FOLDER = "checkpoints"
DATA_SEED = 0  # Every agent and seed learns from the same babbling dataset.
TRAINING_VERSION = 3  # Bump when training changes, so cached checkpoints are not reused. 2: SMPL
# columns train and act together, each on its own module's inputs. 3: validation (early stopping)
# leaves out the VAE's KL term; hyperparameters from hyperparameters.json.

ModelFactory = Callable[..., InverseModel]  # (input_size, action_size, **model settings) -> model
EpochCallback = Callable[[int, float], None]  # (epoch, counted across columns; validation loss)


@dataclasses.dataclass(frozen=True)
class TrainedConfig:
  """Everything a trained agent's weights depend on; its hash names the checkpoint."""

  agent: str
  robot: str
  robot_xml_sha256: str
  views: tuple[str, ...]
  samples: int
  seed: int
  max_epochs: int
  patience: int
  compile: bool
  hyperparameters: tuple[tuple[str, float | int], ...] = ()  # Sorted (name, value) pairs.
  training_version: int = TRAINING_VERSION

  @property
  def key(self) -> str:
    return storage.config_key(self, f"{self.agent}-{self.robot}-seed{self.seed}")


@dataclasses.dataclass
class Controller:
  """One view's forward model and normalisation, with the forward model's running state."""

  view: data.View
  forward: smpl_forward.ForwardModel
  normalisation: data.Normalisation
  forward_state: object = None


def controllers(
  views: list[data.View],
  forwards: list[smpl_forward.ForwardModel],
  normalisations: list[data.Normalisation],
) -> list[Controller]:
  """Each view's controller: its forward model (on the CPU, where agents act, in eval mode) and
  normalisation."""
  return [
    Controller(view, forward.cpu().eval(), scale)
    for view, forward, scale in zip(views, forwards, normalisations)
  ]


class LearnedAgent(base.Agent):
  """Acts with trained controllers; see the module docstring.

  ``inverse`` is one model for all controllers: a centralised baseline (one controller), or SMPL's
  progressive network, whose columns act together (``step_columns``), column k on module k's own
  inputs.
  """

  def __init__(
    self,
    robot: robot_base.SoftArm,
    seed: int,
    inverse: InverseModel,
    controllers: list[Controller],
    error_source: str = "physics",
    candidates: Callable[[], completion.Candidates] | None = None,
  ):
    """``candidates`` builds the babbling poses that complete partial targets (None: this agent
    cannot complete them; ``helper_targets`` ``hold`` and ``share`` still work)."""
    super().__init__(robot, seed)
    self.inverse = inverse
    self.controllers = controllers
    self.error_source = error_source
    self.candidates = candidates
    self.active_modules: tuple[int, ...] | None = None
    self.helper_targets = DEFAULT_HELPER_TARGETS
    self._completer = completion.Completer(
      self._babbling_candidates, self._hold_prediction, robot.length, robot.control_timestep
    )
    self._reset_memory()

  def _babbling_candidates(self) -> completion.Candidates:
    if self.candidates is None:
      raise ValueError(
        f"this {self.robot.name} agent cannot complete a partial target (no babbling data); "
        f"use helper targets hold or share"
      )
    return self.candidates()

  def _reset_memory(self) -> None:
    self._previous_target = None  # x*_t, (num_modules, 6)
    self._start_poses = None
    self._previous_poses = None  # x_{t-1}
    self._poses_before = None  # x_{t-2}
    self._previous_action = np.zeros(self.robot.action_dim)
    self._completer.reset()

  def reset(self, episode: base.EpisodeInfo) -> None:
    if self.error_source not in ERROR_SOURCES:
      raise ValueError(
        f"error_source must be one of {', '.join(ERROR_SOURCES)}, got {self.error_source!r}"
      )
    self._scored = np.array(episode.scored_modules) - 1
    self._reset_memory()
    for controller in self.controllers:
      controller.forward_state = controller.forward.initial_state(1)
    self._inverse_state = self.inverse.initial_state(1)

  def _full_target(self, target: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Every module's target pose (module docstring: ``helper_targets``)."""
    if self.helper_targets not in HELPER_TARGETS:
      raise ValueError(
        f"helper_targets must be one of {', '.join(HELPER_TARGETS)}, got {self.helper_targets!r}"
      )
    if len(self._scored) == self.robot.num_modules and target.shape[1] == 6:
      return target  # Every module's whole pose is given.
    if self.helper_targets in ("complete", "nearest"):
      active_actions = np.repeat(self._module_active(), self.robot.actuators_per_module)
      return self._completer.complete(
        target,
        trajectories.Given(
          tuple(int(module) + 1 for module in self._scored),
          target.shape[1] == recorder.POSE_SIZE,
        ),
        self._previous_poses,
        poses,
        active_actions,
        refine=self.helper_targets == "complete",
        correct=self.error_source == "physics",
      )
    full = self._start_poses.copy()
    if self.helper_targets == "share" and len(self._scored) == 1:
      full = poses.copy()
      full[self._module_active(), :3] += target[0, :3] - poses[self._scored[0], :3]
      full[self._scored] = self._start_poses[self._scored]
    full[self._scored, : target.shape[1]] = target
    return full

  def act(self, observation: dict) -> np.ndarray:
    poses = np.asarray(observation["poses"], dtype=float)
    if self._start_poses is None:
      self._start_poses = poses.copy()
      self._previous_poses = self._poses_before = poses.copy()  # x_{-1} = x_{-2} = x_0
    target = self._full_target(np.asarray(observation["target"], dtype=float), poses)
    action = np.zeros(self.robot.action_dim)
    with torch.no_grad():
      inputs = [
        self._controller_inputs(controller, target, poses) for controller in self.controllers
      ]
      if isinstance(self.inverse, progressive.ProgressiveLSTM):
        outputs, self._inverse_state = self.inverse.step_columns(inputs, self._inverse_state)
      else:
        (single,) = inputs
        step = self.inverse.step(single, self._inverse_state)
        outputs, self._inverse_state = [step.action], step.state
      for controller, output in zip(self.controllers, outputs):
        action[list(controller.view.action_indices)] = controller.normalisation.actions.denormalise(
          output[0].numpy().astype(float)
        )
    action = np.clip(action, -1.0, 1.0)
    action[~np.repeat(self._module_active(), self.robot.actuators_per_module)] = 0.0
    self._previous_target = target
    self._poses_before, self._previous_poses = self._previous_poses, poses
    self._previous_action = action
    return action

  def _hold_prediction(
    self, action: torch.Tensor, previous_poses: np.ndarray, poses: np.ndarray, steps: int
  ) -> torch.Tensor:
    """Every module's poses (num_modules, 6) that the forward models predict after holding
    ``action`` (action_dim,) for ``steps`` control steps from ``previous_poses`` and ``poses``;
    differentiable in ``action``."""
    predicted = {}
    for controller in self.controllers:
      view, scale = controller.view, controller.normalisation
      pick = lambda full: _tensor(
        scale.poses.normalise(view.select(full, self._previous_action)[0])
      )
      actuation = torch.cat(
        [
          _normalised(action[list(view.preceding_action_indices)], scale.preceding_actions),
          _normalised(action[list(view.action_indices)], scale.actions),
        ]
      )[None]
      before, now = pick(previous_poses)[None], pick(poses)[None]
      state = controller.forward.initial_state(1)
      for _ in range(steps):
        after, state = controller.forward.step(before, now, actuation, state)
        before, now = now, after
      poses_of_view = now[0] * _tensor(scale.poses.half_range) + _tensor(scale.poses.centre)
      for index, module in enumerate(view.pose_modules):
        predicted[module] = poses_of_view[
          index * recorder.POSE_SIZE : (index + 1) * recorder.POSE_SIZE
        ]
    if len(predicted) != self.robot.num_modules:
      raise ValueError(
        f"this agent's forward models see modules {sorted(m + 1 for m in predicted)} of "
        f"{self.robot.name}, not every module: it cannot complete a partial target"
      )
    return torch.stack([predicted[module] for module in range(self.robot.num_modules)])

  def _module_active(self) -> np.ndarray:
    """(num_modules,) whether each module acts (``active_modules``)."""
    active = np.ones(self.robot.num_modules, dtype=bool)
    if self.active_modules is not None:
      if not set(self.active_modules) <= set(range(1, self.robot.num_modules + 1)):
        raise ValueError(
          f"active modules must lie in 1 to {self.robot.num_modules} for "
          f"{self.robot.name}, got {tuple(self.active_modules)}"
        )
      active[:] = False
      active[np.array(list(self.active_modules), dtype=int) - 1] = True
    return active

  def _controller_inputs(
    self, controller: Controller, target: np.ndarray, poses: np.ndarray
  ) -> torch.Tensor:
    """The controller's normalised input [x*_{t+1}, e_t, a_{t-1}], (1, input_size)."""
    view, scale = controller.view, controller.normalisation
    as_tensor = lambda values: torch.as_tensor(values, dtype=torch.float32)[None]
    pick = lambda full: scale.poses.normalise(view.select(full, self._previous_action)[0])
    _, previous_own, previous_preceding = view.select(poses, self._previous_action)
    previous_action = (
      scale.actions.normalise(previous_own)
      if self._previous_target is not None
      else np.zeros(view.action_size)
    )
    error = np.zeros(view.pose_size)
    if self._previous_target is not None and self.error_source == "physics":
      error = pick(self._previous_target) - pick(poses)
    elif self._previous_target is not None and self.error_source == "model":
      # x'_t = forward(x_{t-2}, x_{t-1}, actuation a_{t-1}), one step behind as in training.
      actuation = np.concatenate(
        [scale.preceding_actions.normalise(previous_preceding), previous_action]
      )
      predicted, controller.forward_state = controller.forward.step(
        as_tensor(pick(self._poses_before)),
        as_tensor(pick(self._previous_poses)),
        as_tensor(actuation),
        controller.forward_state,
      )
      error = pick(self._previous_target) - predicted[0].numpy()
    return smpl_windows.inverse_inputs(
      as_tensor(pick(target)), as_tensor(error), as_tensor(previous_action)
    )


def _tensor(values: np.ndarray) -> torch.Tensor:
  return torch.as_tensor(values, dtype=torch.float32)


def _normalised(values: torch.Tensor, normaliser: data.MinMaxNormaliser) -> torch.Tensor:
  """``normaliser.normalise`` of a tensor, differentiable."""
  return (values - _tensor(normaliser.centre)) / _tensor(normaliser.half_range)


def training_configs(
  seed: int, profile: profiles.Profile, params: dict | None = None
) -> tuple[training.ForwardTrainingConfig, training.InverseTrainingConfig]:
  """The forward model's config (the paper's, always) and the inverse model's (with ``params``'
  optimiser settings; ``hyperparameters.values``), seeded by ``seed``."""
  common = dict(
    max_epochs=profile.max_epochs, patience=profile.patience, seed=seed, compile=profile.compile
  )
  return (
    training.ForwardTrainingConfig(**common),
    training.InverseTrainingConfig(**common, **hyperparameters.training_settings(params or {})),
  )


def forward_config(seed: int, profile: profiles.Profile) -> training.ForwardTrainingConfig:
  """How the forward models of an agent trained with ``seed`` and ``profile`` are trained."""
  return training_configs(seed, profile)[0]


def _input_size(view: data.View) -> int:
  return smpl_windows.inverse_input_size(view.pose_size, view.action_size)


def _inverse_model(
  views: list[data.View], per_module: bool, make_model: ModelFactory, params: dict
) -> InverseModel:
  """An untrained inverse model for the views: a column per module (the paper's width and
  depth), or one centralised model configured by ``params``' model settings."""
  if per_module:
    inverse = progressive.ProgressiveLSTM()
    for view in views:
      inverse.add_column(_input_size(view), view.action_size)
    return inverse
  (view,) = views
  return make_model(_input_size(view), view.action_size, **hyperparameters.model_settings(params))


def untrained(
  views: list[data.View], per_module: bool, make_model: ModelFactory | None, params: dict
) -> tuple[InverseModel, list[smpl_forward.ForwardModel]]:
  """Untrained inverse (configured by ``params``) and forward models for ``views``, to load a
  checkpoint into."""
  forwards = [
    smpl_forward.ForwardModel(view.preceding_action_size + view.action_size, view.pose_size)
    for view in views
  ]
  return _inverse_model(views, per_module, make_model, params), forwards


def bundle(inverse: InverseModel, forwards: list[smpl_forward.ForwardModel]) -> torch.nn.Module:
  """The module a checkpoint stores: the inverse model and every forward model."""
  return torch.nn.ModuleDict({"inverse": inverse, "forward_models": torch.nn.ModuleList(forwards)})


def _train(
  name: str,
  robot: robot_base.SoftArm,
  views: list[data.View],
  seed: int,
  profile: profiles.Profile,
  per_module: bool,
  make_model: ModelFactory,
  params: dict,
  show: bool,
) -> tuple[InverseModel, list[smpl_forward.ForwardModel], list[data.Normalisation]]:
  """Collects or finds the dataset, then trains (or finds) the forward models and trains the
  inverse model (module docstring)."""
  windows, forwards = trained_forward_models(robot, views, seed, profile, show)
  inverse, _ = train_inverse(
    views,
    windows,
    forwards,
    seed,
    profile,
    per_module,
    make_model,
    params,
    f"{name} {robot.name} seed {seed}",
    show,
  )
  return inverse, forwards, [split.normalisation for split in windows]


def trained_forward_models(
  robot: robot_base.SoftArm,
  views: list[data.View],
  seed: int,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> tuple[list[data.SplitWindows], list[smpl_forward.ForwardModel]]:
  """Each view's windows of the profile's babbling dataset (collected or found) and its frozen
  forward model, trained with ``forward_config(seed, profile)`` or found in the cache that every
  agent and tuning trial reading the same view shares (``forward_models``)."""
  dataset = data.collect(robot, samples=profile.samples, seed=DATA_SEED, progress=show_progress)
  return forward_models.prepare(
    robot,
    views,
    dataset,
    profile.samples,
    DATA_SEED,
    forward_config(seed, profile),
    TRAINING_VERSION,
    f"forward {robot.name} seed {seed}",
    show_progress,
  )


def train_inverse(
  views: list[data.View],
  windows: list[data.SplitWindows],
  forwards: list[smpl_forward.ForwardModel],
  seed: int,
  profile: profiles.Profile,
  per_module: bool,
  make_model: ModelFactory | None,
  params: dict,
  progress_label: str | None = None,
  show_progress: bool = False,
  on_epoch: EpochCallback | None = None,
  restart_diverged: bool = True,
) -> tuple[InverseModel, float]:
  """Trains a fresh inverse model with hyperparameters ``params`` in closed loop through the
  frozen forward models (one per view); returns it and its validation loss. A diverged training
  starts again with half the learning rate (``restart_diverged``; ``smpl.training``), which a
  tuning trial, scoring its own learning rate, turns off.

  The validation loss is the action MSE over the whole arm (normalised units, the aux term left
  out): a baseline's best validation loss, or for SMPL the columns' best losses weighted by their
  modules' action counts (a column's actions do not depend on the columns after it). Columns train
  in order, the earlier ones frozen. ``on_epoch`` gets every epoch (numbered ``column *
  profile.max_epochs + epoch``) and the validation loss so far: the trained columns' best losses
  and the training column's latest, weighted the same way.
  """
  _, inverse_config = training_configs(seed, profile, params)
  device = training.default_device()
  with training.seeded(seed, torch.device("cpu")):
    inverse = _inverse_model(views, per_module, make_model, params)
  action_sizes = [view.action_size for view in views]
  best_losses = []
  for index, view in enumerate(views):
    label = None if progress_label is None else f"inverse {progress_label} {view.name}"
    with progress_bars.epochs(label, profile.max_epochs, show_progress) as bar:
      epoch_end = _epoch_callback(
        bar,
        on_epoch,
        index * profile.max_epochs,
        lambda loss: _action_weighted(best_losses + [loss], action_sizes),
      )
      if per_module:  # Column by column, all acting together; the earlier ones stay frozen.
        inverse.columns.requires_grad_(False)
        inverse.columns[index].requires_grad_(True)
        result = training.train_column_jointly(
          inverse,
          forwards[: index + 1],
          smpl_windows.ModuleWindows(tuple(split.train for split in windows[: index + 1])),
          smpl_windows.ModuleWindows(tuple(split.validation for split in windows[: index + 1])),
          inverse_config,
          device,
          epoch_end,
          restart_diverged=restart_diverged,
        )
      else:
        result = training.train_inverse_model(
          inverse,
          forwards[index],
          windows[index].train,
          windows[index].validation,
          inverse_config,
          device,
          epoch_end,
          restart_diverged,
        )
    best_losses.append(result.best_validation_loss)
  inverse.requires_grad_(False)
  return inverse, _action_weighted(best_losses, action_sizes)


def _epoch_callback(
  bar, on_epoch: EpochCallback | None, first_epoch: int, loss_so_far: Callable[[float], float]
) -> Callable[[training.EpochReport], None]:
  """``smpl.training.fit``'s epoch callback: advances the progress bar, then calls ``on_epoch``."""

  def epoch_end(report: training.EpochReport) -> None:
    if bar is not None:
      bar(report)
    if on_epoch is not None:
      on_epoch(first_epoch + report.epoch, loss_so_far(report.validation_loss))

  return epoch_end


def _action_weighted(losses: list[float], action_sizes: list[int]) -> float:
  """Mean of per-view action MSEs weighted by action count: the MSE over all their actions."""
  sizes = action_sizes[: len(losses)]
  return sum(loss * size for loss, size in zip(losses, sizes)) / sum(sizes)


def trained_config(
  name: str,
  robot: robot_base.SoftArm,
  views: list[data.View],
  seed: int,
  profile: profiles.Profile,
  params: dict,
) -> TrainedConfig:
  """The config that names the checkpoint of agent ``name`` trained with these settings."""
  return TrainedConfig(
    name,
    robot.name,
    robot.physics_sha256(),
    tuple(view.name for view in views),
    profile.samples,
    seed,
    profile.max_epochs,
    profile.patience,
    profile.compile,
    tuple(sorted(params.items())),
  )


def checkpoint_path(
  name: str, robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, per_module: bool
) -> pathlib.Path:
  """Where ``build_agent`` caches the agent's checkpoint (it exists once trained)."""
  views = learners.views(robot, per_module)
  return checkpoint_file(
    trained_config(name, robot, views, seed, profile, hyperparameters.values(name, robot.name))
  )


def cache_files(
  name: str, robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, per_module: bool
) -> list[tuple[pathlib.Path, str]]:
  """The files the data home caches for agent ``name`` of ``seed``, each with its zoo kind: the
  agent's checkpoint, then the forward models it trains through."""
  views = learners.views(robot, per_module)
  forwards = forward_models.configs(
    robot, views, profile.samples, DATA_SEED, forward_config(seed, profile), TRAINING_VERSION
  )
  return [(checkpoint_path(name, robot, seed, profile, per_module), "agent")] + [
    (forward_models.cache_file(config), "forward") for config in forwards
  ]


def checkpoint_file(config: TrainedConfig) -> pathlib.Path:
  """The checkpoint named by ``config``."""
  return storage.softbench_home() / CHECKPOINT_FOLDER / f"{config.key}.pt"


@dataclasses.dataclass
class TrainedModels:
  """What a checkpoint holds: the inverse model, the forward models, the normalisation of each
  named part (a view, or a robot of a protocol) and any further named arrays."""

  inverse: InverseModel
  forwards: list[smpl_forward.ForwardModel]
  normalisations: list[data.Normalisation]
  arrays: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)


def load_or_train(
  path: pathlib.Path,
  config,
  parts: list[str],
  untrained_models: Callable[[], tuple[InverseModel, list[smpl_forward.ForwardModel]]],
  train: Callable[[], TrainedModels],
) -> TrainedModels:
  """The models of the checkpoint at ``path`` (saved for ``config``; taken from the zoo if the
  data home lacks it, ``softbench.zoo``), loaded into ``untrained_models()``. Otherwise, or if
  the file is damaged in any way (``storage.read_cached``: one ``CorruptFileWarning``),
  ``train()``'s, trained so that an interrupted training resumes
  (snapshots in ``snapshot_folder(path)``) and then saved there: normalisation i as
  ``parts[i]/KEY``, the further arrays under their own names (no part's prefix). Another process
  sharing the data home waits meanwhile (``storage.found_or_made``) and then loads it."""
  zoo.restore(path)

  def read(found: pathlib.Path) -> TrainedModels:
    inverse, forwards = untrained_models()
    stored = checkpoint.load_checkpoint(found, bundle(inverse, forwards), config)
    normalisations = [
      data.Normalisation.from_arrays(
        {
          key.removeprefix(f"{part}/"): value
          for key, value in stored.items()
          if key.startswith(f"{part}/")
        }
      )
      for part in parts
    ]
    arrays = {
      key: np.asarray(value) for key, value in stored.items() if key.split("/")[0] not in parts
    }
    return TrainedModels(inverse, forwards, normalisations, arrays)

  return storage.found_or_made(
    path,
    lambda: storage.read_cached(path, read, "checkpoint", "training it again"),
    lambda: _train_and_save(path, config, parts, train),
    "checkpoint",
  )


def _train_and_save(
  path: pathlib.Path, config, parts: list[str], train: Callable[[], TrainedModels]
) -> TrainedModels:
  """``train()``'s models, trained resumably and saved at ``path`` (``load_or_train``)."""
  with snapshots.resumable(snapshot_folder(path)):
    models = train()
  if set(key.split("/")[0] for key in models.arrays) & set(parts):
    raise ValueError(f"further arrays {sorted(models.arrays)} clash with the parts {parts}")
  scales = {
    f"{part}/{key}": value
    for part, scale in zip(parts, models.normalisations)
    for key, value in scale.to_arrays().items()
  }
  checkpoint.save_checkpoint(
    path, bundle(models.inverse, models.forwards), config, {**scales, **models.arrays}
  )
  snapshots.discard(snapshot_folder(path))
  return models


def snapshot_folder(checkpoint_path: pathlib.Path) -> pathlib.Path:
  """Where the training of a checkpoint keeps its snapshots until the checkpoint is written, so
  that an interrupted training resumes (``smpl.snapshots``)."""
  return checkpoint_path.with_suffix(".partial")


def build_agent(
  name: str,
  robot: robot_base.SoftArm,
  seed: int,
  profile: profiles.Profile,
  per_module: bool,
  make_model: ModelFactory | None = None,
  show_progress: bool = False,
) -> LearnedAgent:
  """A trained learned agent: from the checkpoint cache, or trained now and then cached."""
  views = learners.views(robot, per_module)
  params = hyperparameters.values(name, robot.name)
  config = trained_config(name, robot, views, seed, profile, params)

  def train() -> TrainedModels:
    return TrainedModels(
      *_train(name, robot, views, seed, profile, per_module, make_model, params, show_progress)
    )

  models = load_or_train(
    checkpoint_file(config),
    config,
    [view.name for view in views],
    lambda: untrained(views, per_module, make_model, params),
    train,
  )
  inverse, forwards, normalisations = models.inverse, models.forwards, models.normalisations
  inverse.eval()
  return LearnedAgent(
    robot,
    seed,
    inverse,
    controllers(views, forwards, normalisations),
    candidates=lambda: babbling_candidates(robot, profile),
  )


def babbling_candidates(
  robot: robot_base.SoftArm, profile: profiles.Profile
) -> completion.Candidates:
  """The poses of the babbling an agent of ``profile`` learned from (collected if the data home
  lacks it), which complete partial targets (``softbench.agents.completion``)."""
  return completion.Candidates.from_dataset(
    data.collect(robot, samples=profile.samples, seed=DATA_SEED, progress=False)
  )
