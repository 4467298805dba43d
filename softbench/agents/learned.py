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

from smpl import forward_model as smpl_forward
from smpl import progressive
from smpl import windows as smpl_windows
from smpl.inverse import InverseModel
from softbench import data
from softbench import profiles
from softbench.agents import base
from softbench.agents import completion
from softbench.agents import hyperparameters
from softbench.agents import learners
from softbench.learning import checkpoints
from softbench.learning import forward_models
from softbench.learning import inverse as inverse_training
from softbench.records.fields import ERROR_SOURCES
from softbench.records.fields import HELPER_TARGETS
from softbench.robots import base as robot_base
from softbench.robots import recorder
from softbench.suite import trajectories

DEFAULT_HELPER_TARGETS = "complete"


@dataclasses.dataclass(frozen=True)
class Acting:
  """How a learned agent acts (module docstring): the error it reads (``error_source``), how it
  completes a partial target (``helper_targets``) and which modules act at the start of an
  episode (``active_modules``, 1-based; None: every module).

  Raises:
    ValueError: an unknown error source or helper targets (one line).
  """

  error_source: str = "physics"
  helper_targets: str = DEFAULT_HELPER_TARGETS
  active_modules: tuple[int, ...] | None = None

  def __post_init__(self):
    if self.active_modules is not None:  # Any sequence of module numbers, held as a tuple.
      object.__setattr__(self, "active_modules", tuple(int(m) for m in self.active_modules))
    if self.error_source not in ERROR_SOURCES:
      raise ValueError(
        f"error_source must be one of {', '.join(ERROR_SOURCES)}, got {self.error_source!r}"
      )
    if self.helper_targets not in HELPER_TARGETS:
      raise ValueError(
        f"helper_targets must be one of {', '.join(HELPER_TARGETS)}, got {self.helper_targets!r}"
      )


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
    acting: Acting = Acting(),
    candidates: Callable[[], completion.Candidates] | None = None,
  ):
    """``acting``: how it acts (``Acting``), fixed for its life; ``candidates`` builds the
    babbling poses that complete partial targets (None: this agent cannot complete them;
    ``helper_targets`` ``hold`` and ``share`` still work)."""
    super().__init__(robot, seed)
    self.inverse = inverse
    self.controllers = controllers
    self.acting = acting
    self.candidates = candidates
    self._completer = completion.Completer(
      self._babbling_candidates, self._hold_prediction, robot.length, robot.control_timestep
    )
    self._check_modules(acting.active_modules)
    self._active_modules = acting.active_modules
    self._reset_memory()

  @property
  def error_source(self) -> str:
    return self.acting.error_source

  @property
  def helper_targets(self) -> str:
    return self.acting.helper_targets

  @property
  def active_modules(self) -> tuple[int, ...] | None:
    """The modules acting now (``switch_modules``; None: every module)."""
    return self._active_modules

  def with_acting(self, **changes) -> "LearnedAgent":
    """This agent's trained models acting as ``Acting`` with ``changes`` (no copy of weights)."""
    return LearnedAgent(
      self.robot,
      self.seed,
      self.inverse,
      [dataclasses.replace(controller, forward_state=None) for controller in self.controllers],
      dataclasses.replace(self.acting, **changes),
      self.candidates,
    )

  def switch_modules(self, active: tuple[int, ...] | None) -> None:
    """Switches modules on and off within an episode (adaptive activation): from the next action
    on, only ``active`` (1-based; None: every module) act; ``reset`` restores ``acting``'s."""
    self._check_modules(active)
    self._active_modules = None if active is None else tuple(active)

  def _check_modules(self, active: tuple[int, ...] | None) -> None:
    if active is not None and not set(active) <= set(range(1, self.robot.num_modules + 1)):
      raise ValueError(
        f"active modules must lie in 1 to {self.robot.num_modules} for "
        f"{self.robot.name}, got {tuple(active)}"
      )

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
    self._active_modules = self.acting.active_modules
    self._scored = np.array(episode.scored_modules) - 1
    self._reset_memory()
    for controller in self.controllers:
      controller.forward_state = controller.forward.initial_state(1)
    self._inverse_state = self.inverse.initial_state(1)

  def _full_target(self, target: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Every module's target pose (module docstring: ``helper_targets``)."""
    if len(self._scored) == self.robot.num_modules and target.shape[1] == recorder.POSE_SIZE:
      return target  # Every module's whole pose is given.
    if self.helper_targets in ("complete", "nearest"):
      active_actions = np.repeat(self._module_active(), self.robot.actuators_per_module)
      return self._completer.complete(
        target,
        trajectories.Given.of_target(self._scored, target),
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
    if self._active_modules is not None:
      active[:] = False
      active[np.array(list(self._active_modules), dtype=int) - 1] = True
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


def checkpoint_path(
  name: str, robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, per_module: bool
) -> pathlib.Path:
  """Where ``build_agent`` caches the agent's checkpoint (it exists once trained)."""
  views = learners.views(robot, per_module)
  params = hyperparameters.values(name, robot.name)
  return checkpoints.checkpoint_file(
    checkpoints.trained_config(name, robot, views, seed, profile, params)
  )


def cache_files(
  name: str, robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, per_module: bool
) -> list[tuple[pathlib.Path, str]]:
  """The files the data home caches for agent ``name`` of ``seed``, each with its zoo kind: the
  agent's checkpoint, then the forward models it trains through."""
  views = learners.views(robot, per_module)
  forwards = forward_models.configs(
    robot,
    views,
    profile.samples,
    inverse_training.DATA_SEED,
    inverse_training.forward_config(seed, profile),
    checkpoints.TRAINING_VERSION,
  )
  return [(checkpoint_path(name, robot, seed, profile, per_module), "agent")] + [
    (forward_models.cache_file(config), "forward") for config in forwards
  ]


def build_agent(
  name: str,
  robot: robot_base.SoftArm,
  seed: int,
  profile: profiles.Profile,
  per_module: bool,
  make_model: inverse_training.ModelFactory | None = None,
  show_progress: bool = False,
  acting: Acting = Acting(),
) -> LearnedAgent:
  """A trained learned agent acting as ``acting``: from the checkpoint cache, or trained now
  (``softbench.learning``) and then cached."""
  views = learners.views(robot, per_module)
  params = hyperparameters.values(name, robot.name)
  config = checkpoints.trained_config(name, robot, views, seed, profile, params)

  def train() -> checkpoints.TrainedModels:
    windows, forwards = inverse_training.trained_forward_models(
      robot, views, seed, profile, show_progress
    )
    inverse, _ = inverse_training.train_inverse(
      views,
      windows,
      forwards,
      seed,
      profile,
      per_module,
      make_model,
      params,
      f"{name} {robot.name} seed {seed}",
      show_progress,
    )
    return checkpoints.TrainedModels(inverse, forwards, [split.normalisation for split in windows])

  models = checkpoints.load_or_train(
    checkpoints.checkpoint_file(config),
    config,
    [view.name for view in views],
    lambda: inverse_training.untrained(views, per_module, make_model, params),
    train,
  )
  models.inverse.eval()
  return LearnedAgent(
    robot,
    seed,
    models.inverse,
    controllers(views, models.forwards, models.normalisations),
    acting,
    candidates=lambda: babbling_candidates(robot, profile),
  )


def babbling_candidates(
  robot: robot_base.SoftArm, profile: profiles.Profile
) -> completion.Candidates:
  """The poses of the babbling an agent of ``profile`` learned from (collected if the data home
  lacks it), which complete partial targets (``softbench.agents.completion``)."""
  return completion.Candidates.from_dataset(
    data.collect(robot, samples=profile.samples, seed=inverse_training.DATA_SEED, progress=False)
  )
