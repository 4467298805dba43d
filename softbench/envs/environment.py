"""A softbench task as a ``gymnasium.Env``: the same physics, targets, reward and seeds as
``suite.load``, through Gymnasium's API.

Observations are one flat ``Box`` (default) or a ``Dict`` of the task's named arrays:

  poses            (num_modules, 6)  every module's tip: position (m), orientation vector
  target           (scored, 3 or 6)  what to reach by the end of this step (reach: position)
  previous_action  (action_dim,)     the action held during the last step, in [-1, 1]

Positions lie within ``trajectories.REACH_FACTOR`` arm lengths of the base (the world origin),
orientation components within [-1, 1] (plus ``trajectories.UNIT_TOLERANCE`` for targets). The
flat form concatenates them in that order, each row-major; ``observation_layout`` gives
the slice of each. Actions are ``Box(-1, 1)``. The episode ends with ``truncated`` when the
task's reference (or reach's time) runs out; no state of the arm ends it (``terminated`` is
always False). ``reset(seed=s)`` starts the episode that ``suite.load(..., seed=s)`` starts.

``step``'s ``info`` scores the step as the leaderboard does (``softbench.metrics``): each scored
module's pose after the step against the target it was shown before it, per scored module
(arrays in the order of ``info["scored_modules"]``, 1-based):

  position_error_mm             (scored,)  Euclidean distance of the tip to its target (mm)
  orientation_error_deg         (scored,)  angle to the target's orientation (absent for reach)
  normalised_tip_error_percent  (scored,)  position error / the arm's length (%)

``scoring.score_policy`` averages them over an episode and seeds into the leaderboard's figures.
"""

from typing import Any

import gymnasium
from gymnasium import spaces
import numpy as np

from softbench import metrics
from softbench import robots
from softbench import suite
from softbench.data import seeding
from softbench.rendering import live
from softbench.suite import trajectories

OBSERVATION_FORMS = ("flat", "dict")
RENDER_MODES = ("rgb_array",)
KEYS = ("poses", "target", "previous_action")  # The observation's parts, in the flat order.


def flatten(named: dict) -> np.ndarray:
  """The flat form (float64) of an observation of named parts (``KEYS``)."""
  return np.concatenate([np.asarray(named[key], np.float64).ravel() for key in KEYS])


def layout(shapes: dict[str, tuple[int, ...]]) -> dict[str, slice]:
  """Where each part of ``shapes`` (by name, ``KEYS``) lies in the flat form."""
  slices, start = {}, 0
  for key in KEYS:
    size = int(np.prod(shapes[key]))
    slices[key] = slice(start, start + size)
    start += size
  return slices


def observation_in(named: dict, form: str) -> np.ndarray | dict:
  """The observation of named parts (``KEYS``) in ``form`` (``OBSERVATION_FORMS``), float64."""
  if form == "dict":
    return {key: np.array(named[key], dtype=np.float64) for key in KEYS}
  return flatten(named)


def errors(robot: robots.SoftArm, task, poses: np.ndarray, target: np.ndarray) -> dict[str, Any]:
  """``step``'s info: the errors of ``poses`` (num_modules, 6) reached by a step of ``task``
  (a ``SoftArmTask``) against the ``target`` it showed before it, per scored module. Leading
  axes (many arms of one task) give errors with the same leading axes."""
  scored = tuple(task.scored_modules())
  achieved = np.asarray(poses)[..., np.array(scored) - 1, : target.shape[-1]]
  info = {
    "scored_modules": scored,
    "position_error_mm": metrics.position_error_mm(achieved, target),
    "normalised_tip_error_percent": metrics.normalised_tip_error_percent(
      achieved, target, robot.length
    ),
  }
  if target.shape[-1] == 6:
    info["orientation_error_deg"] = metrics.orientation_error_deg(achieved, target)
  return info


def _pose_box(spec, robot: robots.SoftArm) -> spaces.Box:
  """The Box of poses or targets (rows of position, then orientation vector if given): positions
  within ``REACH_FACTOR`` arm lengths of the base, as the suite accepts targets, and orientation
  components within a unit vector's (and its tolerance)."""
  reach = trajectories.REACH_FACTOR * robot.length
  unit = 1.0 + trajectories.UNIT_TOLERANCE
  row = np.array([reach] * 3 + [unit] * 3)[: spec.shape[-1]]
  high = np.broadcast_to(row, spec.shape).astype(spec.dtype)
  return spaces.Box(-high, high, spec.shape, spec.dtype)


class SoftArmEnv(gymnasium.Env):
  """``task`` on ``robot`` (a name, e.g. ``tendon-3``, or a ``robots.SoftArm``).

  Args:
    robot: robot name or spec; faults (``robot.with_faults``) change the physics as in the suite.
    task: one of ``suite.TASKS``.
    observation: ``"flat"`` (a Box) or ``"dict"``.
    render_mode: None or ``"rgb_array"`` (headless, the videos' scene and camera).
    width, height: frame size of ``render`` (pixels).
    camera: one of ``rendering.options.CAMERAS``.
    **task_options: the task's options, as ``suite.load`` takes them (``length``, ``module``,
      ``steps``, ``trajectory``, ``initial_actuation``).

  Raises:
    ValueError: an unknown robot, task, option or observation form, or a bad option value
      (one line).
  """

  metadata = {"render_modes": list(RENDER_MODES), "render_fps": None}

  def __init__(
    self,
    robot: str | robots.SoftArm,
    task: str,
    observation: str = "flat",
    render_mode: str | None = None,
    width: int | None = None,
    height: int | None = None,
    camera: str | None = None,
    **task_options,
  ):
    if observation not in OBSERVATION_FORMS:
      raise ValueError(
        f"observation must be one of {', '.join(OBSERVATION_FORMS)}, got {observation!r}"
      )
    if render_mode is not None and render_mode not in RENDER_MODES:
      raise ValueError(
        f"render_mode must be None or one of {', '.join(RENDER_MODES)}, got {render_mode!r}"
      )
    self.robot = robots.make(robot) if isinstance(robot, str) else robot
    self.task_name = task
    self._environment = suite.load(self.robot, task, **task_options)
    self._observation_form = observation
    self.render_mode = render_mode
    self.metadata = {**self.metadata, "render_fps": 1.0 / self.robot.control_timestep}
    named = self._environment.observation_spec()
    action = named["previous_action"]
    named_spaces = {
      "poses": _pose_box(named["poses"], self.robot),
      "target": _pose_box(named["target"], self.robot),
      "previous_action": spaces.Box(
        float(action.minimum), float(action.maximum), action.shape, action.dtype
      ),
    }
    self.observation_shapes = {key: tuple(named[key].shape) for key in KEYS}
    self.observation_layout = layout(self.observation_shapes)
    if observation == "dict":
      self.observation_space = spaces.Dict(named_spaces)
    else:
      self.observation_space = spaces.Box(
        np.concatenate([space.low.ravel() for space in named_spaces.values()]),
        np.concatenate([space.high.ravel() for space in named_spaces.values()]),
        dtype=np.float64,
      )
    action = self._environment.action_spec()
    self.action_space = spaces.Box(-1.0, 1.0, action.shape, np.float32)
    self._view = None
    if render_mode is not None:
      self._view = live.LiveView(self.robot, width=width, height=height, camera=camera)
    elif (width, height, camera) != (None, None, None):
      raise ValueError("width, height and camera need render_mode='rgb_array'")
    self._ended = True

  @property
  def dm_env(self):
    """The ``dm_control.rl.control.Environment`` underneath (its physics and task)."""
    return self._environment

  def _observation(self, named: dict) -> np.ndarray | dict:
    return observation_in(named, self._observation_form)

  def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
    """Starts an episode; ``seed`` gives the start and targets ``suite.load(seed=seed)`` gives."""
    if options:
      raise ValueError(
        f"reset takes no options, got {sorted(options)}; pass task options to gymnasium.make"
      )
    if seed is not None:
      seeding.check_seed(seed)
      self._environment.task.reseed(seed)
    super().reset(seed=seed)
    time_step = self._environment.reset()
    self._ended = False
    self._target = time_step.observation["target"]
    if self._view is not None:
      self._view.start(self._environment.physics, self._environment.task)
    return self._observation(time_step.observation), {}

  def step(self, action):
    if self._ended:
      raise RuntimeError("the episode has ended (or not started); call reset() first")
    time_step = self._environment.step(np.asarray(action, dtype=np.float64))
    self._ended = time_step.last()
    info = errors(self.robot, self._environment.task, time_step.observation["poses"], self._target)
    self._target = time_step.observation["target"]
    observation = self._observation(time_step.observation)
    return observation, float(time_step.reward), False, self._ended, info

  def render(self) -> np.ndarray | None:
    """(height, width, 3) uint8: the arm and the current targets, with render_mode
    ``"rgb_array"``; None without a render mode."""
    if self._view is None:
      return None
    return self._view.render(self._environment.physics, self._environment.task)

  def close(self) -> None:
    if self._view is not None:
      self._view.close()
      self._view = None
