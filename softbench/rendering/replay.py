"""Replays a recorded episode in physics, so that it can be drawn at any moment of every step.

An episode is deterministic per seed: the task's environment, reset with the same seed, starts
from the same state, and holding the recorded actions reproduces the recorded poses bit for bit
(``SoftArmPhysics.step`` is ``mj_step``; splitting a control period into pieces for in-between
frames does not change the state). The replay checks that it does, step by step.
"""

import dataclasses
from typing import Iterator

import numpy as np

from softbench import episodes
from softbench import suite
from softbench.robots import base
from softbench.robots import physics as arm_physics

POSE_TOLERANCE = 1e-9  # (m, and unit-vector entries) Largest replay deviation from the episode.


@dataclasses.dataclass(frozen=True)
class Replay:
  """An episode and what it needs to be replayed: the environment it ran in and a title.

  Attributes:
    robot: The robot spec.
    task: Task name.
    seed: The environment's seed (``suite.load(..., seed=seed)``).
    task_options: The task's options (episode length, trajectory...), as given to ``suite.load``.
    episode: What happened (``evaluation.run_episode``).
    title: A line saying what the episode is, e.g. ``smpl on spiral (tendon-3), seed 0``.
  """

  robot: base.SoftArm
  task: str
  seed: int
  task_options: dict
  episode: episodes.Episode
  title: str

  @property
  def steps(self) -> int:
    return len(self.episode.actions)


def _check(physics: arm_physics.SoftArmPhysics, expected: np.ndarray, step: int) -> None:
  deviation = float(np.max(np.abs(physics.module_poses() - expected)))
  if deviation > POSE_TOLERANCE:
    raise RuntimeError(
      f"the replay left the recorded episode at control step {step} (pose "
      f"entries differ by up to {deviation:.3g}); was it recorded with other "
      f"task options or another seed?"
    )


def moments(
  replay: Replay, frames_per_step: int
) -> Iterator[tuple[float, arm_physics.SoftArmPhysics]]:
  """Yields (time in control steps, physics at that time): the start, then ``frames_per_step``
  moments evenly spaced over every control period, the last at its end.

  Raises:
    ValueError: more frames per step than physics steps per control period.
    RuntimeError: the replay does not reproduce the episode's poses.
  """
  env = suite.load(replay.robot, replay.task, seed=replay.seed, **replay.task_options)
  env.reset()
  physics = env.physics
  sub_steps = int(round(replay.robot.control_timestep / physics.timestep()))
  if frames_per_step > sub_steps:
    raise ValueError(
      f"frames per step must be at most {sub_steps} for {replay.robot.name} "
      f"(physics steps per control period), got {frames_per_step}"
    )
  bounds = np.linspace(0, sub_steps, frames_per_step + 1).round().astype(int)
  _check(physics, replay.episode.poses[0], 0)
  yield 0.0, physics
  for step, action in enumerate(replay.episode.actions):
    physics.set_action(action)
    for piece in range(frames_per_step):
      physics.step(int(bounds[piece + 1] - bounds[piece]))
      yield step + (piece + 1) / frames_per_step, physics
    _check(physics, replay.episode.poses[step + 1], step + 1)
