"""Measurements of a robot's physics, as stated in the model READMEs and ``softbench robots``.

Everything runs headless on the CPU with MuJoCo's own ``rollout``; all randomness comes from
the seed passed in, so the same robot gives the same figures.
"""

import time

import mujoco
from mujoco import rollout
import numpy as np

from softbench.robots import base
from softbench.robots import chain
from softbench.robots import recorder

SETTLE_SECONDS = 3.0  # (s) Time given to reach equilibrium after a change of action.
SETTLED_TOLERANCE = 0.001  # (m) Tip distance from its final position that counts as settled.
WORKSPACE_SAMPLES = 200  # Random actions whose poses outline the workspace.
DISCRETISATION_REFINEMENT = 4  # The finer model has this many times more segments.


def tip_trajectory(
  robot: base.SoftArm, actions: np.ndarray, hold_seconds: float, model: mujoco.MjModel | None = None
) -> np.ndarray:
  """Every module's tip position (steps, modules, 3) in m, each action held ``hold_seconds``.

  Raises:
    FloatingPointError: the simulation became unstable.
  """
  poses = recorder.PoseRecorder(robot, model=model)
  data = mujoco.MjData(poses.model)
  steps = int(round(hold_seconds / poses.model.opt.timestep))
  controls = np.repeat(robot.action_to_ctrl(np.atleast_2d(actions)), steps, axis=0)
  states, _ = rollout.rollout(poses.model, data, poses.rest_state()[None], controls[None])
  if data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number or not np.all(np.isfinite(states)):
    raise FloatingPointError(f"{robot.name}: simulation unstable")
  return poses.poses(states[0])[..., :3]


def equilibrium(
  robot: base.SoftArm,
  action: np.ndarray,
  seconds: float = SETTLE_SECONDS,
  model: mujoco.MjModel | None = None,
) -> np.ndarray:
  """Tip positions (modules, 3) in m after holding ``action`` for ``seconds`` from rest."""
  return tip_trajectory(robot, action, seconds, model)[-1]


def full_bend_action(robot: base.SoftArm, module: int) -> np.ndarray:
  """The action that bends ``module`` fully towards world +x and leaves the others at zero."""
  action = np.zeros(robot.action_dim)
  action[robot.module_action_slices()[module - 1]] = robot.bend_action_pattern(module)
  return action


def tip_axes(
  robot: base.SoftArm, action: np.ndarray, seconds: float = SETTLE_SECONDS, gravity: bool = True
) -> tuple[np.ndarray, np.ndarray]:
  """Every module's tip axis (modules, 3) at rest and after holding ``action`` for ``seconds``
  from rest, with or without gravity."""
  model = robot.compile()
  if not gravity:
    model.opt.gravity[:] = 0.0
  data = mujoco.MjData(model)
  mujoco.mj_kinematics(model, data)
  sites = [model.site(chain.tip_site_name(k)).id for k in range(1, robot.num_modules + 1)]
  rest = data.site_xmat[sites].reshape(-1, 3, 3)[:, :, 2].copy()
  data.ctrl[:] = robot.action_to_ctrl(action)
  mujoco.mj_step(model, data, nstep=int(round(seconds / model.opt.timestep)))
  return rest, data.site_xmat[sites].reshape(-1, 3, 3)[:, :, 2].copy()


def _angles(first: np.ndarray, second: np.ndarray) -> np.ndarray:
  """Angles (deg) between unit vectors, row by row."""
  return np.degrees(np.arccos(np.clip(np.sum(first * second, axis=-1), -1.0, 1.0)))


def bend_angle(
  robot: base.SoftArm, action: np.ndarray, module: int = 1, seconds: float = SETTLE_SECONDS
) -> float:
  """Angle (deg) between a module's tip axis at rest and after holding ``action``."""
  rest, bent = tip_axes(robot, action, seconds)
  return float(_angles(rest, bent)[module - 1])


def own_bend_angles(robot: base.SoftArm, seconds: float = SETTLE_SECONDS) -> np.ndarray:
  """Per module k, the angle (deg) between its tip axis and its base's (the preceding module's
  tip axis, or the arm's axis at rest) after holding full actuation of module k alone."""
  angles = []
  for module in range(1, robot.num_modules + 1):
    rest, bent = tip_axes(robot, full_bend_action(robot, module), seconds)
    base_axis = rest[0] if module == 1 else bent[module - 2]
    angles.append(float(_angles(base_axis, bent[module - 1])))
  return np.array(angles)


def gravity_free_tilts(
  robot: base.SoftArm, module: int, seconds: float = SETTLE_SECONDS
) -> np.ndarray:
  """Angle (deg) of every module's tip axis from rest after holding full actuation of ``module``
  alone, gravity off: how far one module's actuators turn the others."""
  rest, bent = tip_axes(robot, full_bend_action(robot, module), seconds, gravity=False)
  return _angles(rest, bent)


def settling_time(robot: base.SoftArm, seconds: float = SETTLE_SECONDS) -> float:
  """Seconds until the end effector stays within ``SETTLED_TOLERANCE`` of its final position
  after a step from rest to full actuation of module 1."""
  model = robot.compile()
  tips = tip_trajectory(robot, full_bend_action(robot, 1), seconds, model)[:, -1]
  moving = np.flatnonzero(np.linalg.norm(tips - tips[-1], axis=1) > SETTLED_TOLERANCE)
  return 0.0 if len(moving) == 0 else float((moving[-1] + 1) * model.opt.timestep)


def workspace_extent(
  robot: base.SoftArm, seed: int = 0, samples: int = WORKSPACE_SAMPLES
) -> np.ndarray:
  """(3, 2) min and max (m) of the end effector over random actions, each held one control
  period, recorded at the end of every period as in motor babbling."""
  actions = np.random.default_rng(seed).uniform(-1, 1, (samples, robot.action_dim))
  model = robot.compile()
  steps = int(round(robot.control_timestep / model.opt.timestep))
  tips = tip_trajectory(robot, actions, robot.control_timestep, model)[steps - 1 :: steps, -1]
  return np.stack([tips.min(axis=0), tips.max(axis=0)], axis=1)


def simulation_speed(robot: base.SoftArm, seconds: float = 5.0, seed: int = 0) -> dict:
  """Physics steps per second and real-time factor on one thread, under random actuation."""
  model = robot.compile()
  periods = max(1, int(round(seconds / robot.control_timestep)))
  actions = np.random.default_rng(seed).uniform(-1, 1, (periods, robot.action_dim))
  steps = int(round(robot.control_timestep / model.opt.timestep))
  controls = np.repeat(robot.action_to_ctrl(actions), steps, axis=0)[None]
  data, initial = mujoco.MjData(model), recorder.PoseRecorder(robot, model=model).rest_state()
  start = time.perf_counter()
  rollout.rollout(model, data, initial[None], controls)
  elapsed = time.perf_counter() - start
  return {
    "steps_per_second": controls.shape[1] / elapsed,
    "real_time_factor": controls.shape[1] * model.opt.timestep / elapsed,
  }


def discretisation_actions(
  robot: base.SoftArm, seed: int = 0, random_actions: int = 3, random_scale: float = 0.5
) -> np.ndarray:
  """Full bending of each module alone, and a few random actions scaled by ``random_scale``."""
  rng = np.random.default_rng(seed)
  actions = [full_bend_action(robot, k) for k in range(1, robot.num_modules + 1)]
  actions += list(random_scale * rng.uniform(-1, 1, (random_actions, robot.action_dim)))
  return np.array(actions)


def discretisation_error(
  robot: base.SoftArm, actions: np.ndarray, factor: int = DISCRETISATION_REFINEMENT
) -> np.ndarray:
  """End-effector distance (m) at equilibrium between ``robot`` and ``robot.refined(factor)``,
  for each action."""
  finer = robot.refined(factor)
  coarse_model, fine_model = robot.compile(), finer.compile()
  return np.array(
    [
      np.linalg.norm(
        equilibrium(robot, action, model=coarse_model)[-1]
        - equilibrium(finer, action, model=fine_model)[-1]
      )
      for action in actions
    ]
  )
