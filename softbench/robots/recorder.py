"""Drives a robot with action sequences and records every module's pose after each control step.

One recorder serves motor babbling, reference trajectories and replay checks. Episodes run side
by side as one ``ArmBatch`` (``softbench.robots.batch``, its ``cpu`` backend: MuJoCo's thread
pool), one control period per call, so that every episode advances in step with the others and a
long recording can be saved and resumed between periods from full physics states, bit for bit
(``mj_step`` with the same controls).
"""

import functools
from typing import Callable

import mujoco
import numpy as np

from softbench.robots import base
from softbench.robots import batch
from softbench.robots import chain

POSE_SIZE = batch.POSE_SIZE
STATE_SPEC = batch.STATE_SPEC
# Recordings from rest that ``from_rest`` keeps per process: a 1,000-step reference of a
# 5-module arm holds 240 kB of poses, a reach target's 4 to 16 poses 1 to 2.3 kB.
FROM_REST_CACHE_SIZE = 64


class PoseRecorder:
  """Records module poses of ``robot`` under held actions, on ``workers`` threads."""

  def __init__(self, robot: base.SoftArm, workers: int = 1, model: mujoco.MjModel | None = None):
    """``model``: the robot's compiled model to simulate (default ``robot.compile()``), e.g. a
    copy of an environment's, which a model-based agent plans on."""
    if workers < 1:
      raise ValueError(f"workers must be at least 1, got {workers}")
    self.robot = robot
    self.workers = workers
    self.model = model if model is not None else robot.compile()
    self.steps_per_action = int(round(robot.control_timestep / self.model.opt.timestep))
    self._scratch = mujoco.MjData(self.model)
    self._sites = np.array(
      [self.model.site(chain.tip_site_name(k)).id for k in range(1, robot.num_modules + 1)]
    )

  @property
  def state_size(self) -> int:
    return mujoco.mj_stateSize(self.model, STATE_SPEC)

  def rest_state(self) -> np.ndarray:
    """Full physics state of the arm at rest (reference configuration, zero velocity)."""
    data = mujoco.MjData(self.model)
    state = np.empty(self.state_size)
    mujoco.mj_getState(self.model, data, state, STATE_SPEC)
    return state

  def poses(self, states: np.ndarray) -> np.ndarray:
    """(..., num_modules, 6) module poses of full physics states (..., state_size)."""
    states = np.asarray(states, dtype=float)
    flat = states.reshape(-1, self.state_size)
    poses = batch.poses_of_states(self.model, self._scratch, self._sites, flat)
    return poses.reshape(states.shape[:-1] + poses.shape[1:])

  def record(
    self,
    actions: np.ndarray,
    initial_states: np.ndarray | None = None,
    on_step: Callable[[int], None] | None = None,
  ) -> tuple[np.ndarray, np.ndarray]:
    """Holds each action for one control period, episode by episode in parallel.

    Args:
      actions: (episodes, steps, action_dim) in [-1, 1].
      initial_states: (episodes, state_size) full physics states; the rest state if None.
      on_step: called with the number of episodes after each control period (for progress).

    Returns:
      poses: (episodes, steps + 1, num_modules, 6), the initial poses first.
      final_states: (episodes, state_size), from which a later call continues exactly.

    Raises:
      ValueError: actions of the wrong shape or outside [-1, 1].
      FloatingPointError: the simulation of an episode became unstable.
    """
    actions = np.asarray(actions, dtype=float)
    if actions.ndim != 3 or actions.shape[2] != self.robot.action_dim:
      raise ValueError(
        f"actions must be (episodes, steps, {self.robot.action_dim}), got {actions.shape}"
      )
    if not np.all(np.isfinite(actions)) or np.any(np.abs(actions) > 1.0):
      raise ValueError("actions must be finite and lie in [-1, 1]")
    episodes, steps = actions.shape[:2]
    poses = np.empty((episodes, steps + 1, len(self._sites), POSE_SIZE))
    with batch.cpu(self.robot, episodes, threads=self.workers, model=self.model) as arms:
      if initial_states is not None:
        arms.set_states(np.asarray(initial_states, dtype=float).reshape(episodes, -1))
      poses[:, 0] = arms.poses()
      for step in range(steps):
        try:
          arms.hold(actions[:, step])
        except FloatingPointError as error:
          raise FloatingPointError(f"{error} at control step {step}") from None
        poses[:, step + 1] = arms.poses()
        if on_step is not None:
          on_step(episodes)
      return poses, arms.states()


def from_rest(robot: base.SoftArm, actions: np.ndarray) -> np.ndarray:
  """The poses (steps + 1, num_modules, 6) of ``robot`` holding ``actions`` (steps, action_dim)
  one control period each from rest, as ``PoseRecorder(robot).record`` records them; read-only.

  Simulated once per process for equal robots and actions (MuJoCo gives the same states for the
  same model and controls, bit for bit): reach targets and references are asked for again by
  every environment with the same seed or shape, e.g. each agent's episodes of a sweep worker."""
  actions = np.ascontiguousarray(actions, dtype=float)
  return _from_rest(robot, actions.shape, actions.tobytes())


@functools.lru_cache(maxsize=FROM_REST_CACHE_SIZE)
def _from_rest(robot: base.SoftArm, shape: tuple[int, ...], actions: bytes) -> np.ndarray:
  poses, _ = PoseRecorder(robot).record(np.frombuffer(actions).reshape(shape)[None])
  poses = poses[0]
  poses.flags.writeable = False
  return poses
