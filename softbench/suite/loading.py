"""Building a task's environment: what ``softbench.suite.load`` and ``build_task`` run (they load
dm_control and MuJoCo, so ``softbench.suite`` imports this module on their first use)."""

import inspect

from dm_control.rl import control
import numpy as np

from softbench import robots
from softbench.data import seeding
from softbench.robots import physics as arm_physics
from softbench.robots import versions
from softbench.suite import base
from softbench.suite import registry


def gives_whole_targets(robot: str | robots.SoftArm, task: str, **task_kwargs) -> bool:
  """Whether ``task`` (with these options) gives every module's whole pose as its target
  (``TaskEntry.partial_targets``); a learned agent completes any other target
  (``softbench.agents.completion``)."""
  arm = robots.make(robot) if isinstance(robot, str) else robot
  return not registry.describe(task).leaves_part_out(arm, task_kwargs)


def build_task(
  robot: str | robots.SoftArm, task: str, seed=None, **task_kwargs
) -> tuple[robots.SoftArm, base.SoftArmTask]:
  """The robot (faults included) and the task object of ``load``, without physics: what a batch
  of arms (``softbench.envs.vector``) runs one task object per arm of. Arguments and errors as
  ``load``'s."""
  entry = registry.describe(task)
  build = entry.builder()
  arm = robots.make(robot) if isinstance(robot, str) else robot
  if not isinstance(arm, robots.SoftArm):
    raise ValueError(f"robot must be a name or a SoftArm, got {robot!r}")
  options = set(inspect.signature(build).parameters) - {"robot", "random"}
  unknown = sorted(set(task_kwargs) - options)
  if unknown:
    raise ValueError(
      f"task {task!r} has no option {unknown[0]!r}; its options: {', '.join(sorted(options))}"
    )
  if seed is not None and not isinstance(seed, np.random.RandomState):
    seeding.check_seed(seed)
  # Targets come from the robot as designed: an actuator fault changes the physics, not the task.
  return arm, build(arm.without_faults(), random=seed, **task_kwargs)


def load(
  robot: str | robots.SoftArm,
  task: str,
  seed=None,
  environment_kwargs: dict | None = None,
  **task_kwargs,
) -> control.Environment:
  """The environment of ``task`` on ``robot`` (a name such as ``tendon-3``, or a robot spec).

  The physics is ``robot``'s, faults included (``robot.with_faults``); the targets are those of
  the healthy robot, so that errors with and without a fault compare.

  Args:
    robot: robot name or ``SoftArm`` instance.
    task: one of ``suite.TASKS``.
    seed: seed of the task's random start (an int, a ``numpy.random.RandomState`` or None).
    environment_kwargs: extra keyword arguments of ``control.Environment``.
    **task_kwargs: the task's options, e.g. ``length`` (tracking), ``module`` and ``steps``
      (reach), ``trajectory`` and ``given`` (custom), ``initial_actuation`` (all).

  Raises:
    ValueError: unknown robot or task, an invalid task option, or a seed that is not an integer
      from 0 to ``seeding.MAX_SEED`` (one line).
  """
  arm, built = build_task(robot, task, seed, **task_kwargs)
  physics = arm_physics.SoftArmPhysics.from_robot(arm)
  options = {"legacy_step": versions.current().legacy_step, **(environment_kwargs or {})}
  return control.Environment(physics, built, control_timestep=arm.control_timestep, **options)
