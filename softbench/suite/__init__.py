"""The softbench task suite, in the style of ``dm_control.suite``.

``load(robot, task, seed)`` returns a ``dm_control.rl.control.Environment``. Every task exists
for every robot; ``ALL_TASKS`` lists the (robot, task) pairs of the registered robots and
``BENCHMARKING`` those tagged ``benchmarking`` (dm_control's convention; so far every one).
``custom`` follows a user's trajectory (``trajectory=ARRAY_OR_PATH``; ``given="2:position"``
when it gives only part of the target, ``trajectories.Given``) and is in neither list, as it
needs one.

A task is a ``TaskEntry`` in the registry (``registry``): ``register`` adds one, and
``tracking_task`` a tracking task from the one function that traces its reference
(``shapes``: ``babbling``, ``circle``, ``rectangle``, ``spiral``). ``TASKS``, ``ALL_TASKS`` and
``BENCHMARKING`` are read from the registry on every access, so they include later registrations.

One control step lasts the robot's control period (``robot.control_timestep``): 1 s for the
tendon arms (1 Hz, the paper's simulator; tendon-5, the slowest, settles in 0.72 s) and 0.2 s
for the pneumatic arm (5 Hz, as on the real robot).
"""

import inspect

from dm_control.rl import control
import numpy as np

from softbench import robots
from softbench.data import seeding
from softbench.robots import physics as arm_physics
from softbench.robots import versions
from softbench.suite import base
from softbench.suite import reach
from softbench.suite import registry
from softbench.suite import shapes  # noqa: F401  Registers babbling, circle, rectangle, spiral.
from softbench.suite import tracking
from softbench.suite import trajectories

TaskEntry = registry.TaskEntry
describe = registry.describe
on_register = registry.on_register
register = registry.register
tracking_task = tracking.tracking_task


def _custom_task(
  robot,
  trajectory=None,
  given: trajectories.Given | str | None = None,
  initial_actuation: float = base.INITIAL_ACTUATION,
  random=None,
) -> base.SoftArmTask:
  if trajectory is None:
    raise ValueError(
      "task 'custom' needs a trajectory (trajectory=ARRAY_OR_PATH, or --trajectory FILE)"
    )
  mask = trajectories.as_given(given, robot)
  return tracking.Tracking(
    robot,
    trajectories.load_trajectory(trajectory, robot, mask),
    initial_actuation=initial_actuation,
    random=random,
    given=mask,
  )


# After the tracking shapes (the import of ``shapes``), in the order the tables list tasks.
register(
  "reach",
  TaskEntry(
    build=reach.Reach,
    tags=("benchmarking",),
    description="bring one module's tip to a virtual point (position only)",
    paper_robot="pneumatic-433",  # The paper reaches with its real, pneumatic arm.
    length_option="steps",
    partial_targets=lambda robot, options: True,
  ),
)
register(
  "custom",
  TaskEntry(
    build=_custom_task,
    tags=("tracking", "user"),
    description="follow your own trajectory (.npy or .csv, one target per row)",
    paper_robot="tendon-3",
    length_option=None,
    partial_targets=lambda robot, options: (
      trajectories.as_given(options.get("given"), robot)
      not in (None, trajectories.Given.whole(robot))
    ),
  ),
)

_LISTS = {
  "TASKS": registry.names,
  "ALL_TASKS": registry.pairs,
  "BENCHMARKING": lambda: registry.pairs("benchmarking"),
}


def __getattr__(name: str):
  """``TASKS`` (every task's name), ``ALL_TASKS`` and ``BENCHMARKING``, as registered now."""
  if name in _LISTS:
    return _LISTS[name]()
  raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def length_options(task: str, steps: int | None) -> dict:
  """The options of ``load`` that make ``task``'s episodes ``steps`` control steps long ({} for
  None, or for ``custom``, whose trajectory sets its length)."""
  option = describe(task).length_option
  return {} if steps is None or option is None else {option: steps}


def gives_whole_targets(robot: str | robots.SoftArm, task: str, **task_kwargs) -> bool:
  """Whether ``task`` (with these options) gives every module's whole pose as its target
  (``TaskEntry.partial_targets``); a learned agent completes any other target
  (``softbench.agents.completion``)."""
  partial = describe(task).partial_targets
  arm = robots.make(robot) if isinstance(robot, str) else robot
  return partial is None or not partial(arm, task_kwargs)


def build_task(
  robot: str | robots.SoftArm, task: str, seed=None, **task_kwargs
) -> tuple[robots.SoftArm, base.SoftArmTask]:
  """The robot (faults included) and the task object of ``load``, without physics: what a batch
  of arms (``softbench.envs.vector``) runs one task object per arm of. Arguments and errors as
  ``load``'s."""
  entry = describe(task)
  arm = robots.make(robot) if isinstance(robot, str) else robot
  if not isinstance(arm, robots.SoftArm):
    raise ValueError(f"robot must be a name or a SoftArm, got {robot!r}")
  options = set(inspect.signature(entry.build).parameters) - {"robot", "random"}
  unknown = sorted(set(task_kwargs) - options)
  if unknown:
    raise ValueError(
      f"task {task!r} has no option {unknown[0]!r}; its options: {', '.join(sorted(options))}"
    )
  if seed is not None and not isinstance(seed, np.random.RandomState):
    seeding.check_seed(seed)
  # Targets come from the robot as designed: an actuator fault changes the physics, not the task.
  return arm, entry.build(arm.without_faults(), random=seed, **task_kwargs)


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
    task: one of ``TASKS``.
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


__all__ = [
  "ALL_TASKS",
  "BENCHMARKING",
  "TASKS",
  "TaskEntry",
  "build_task",
  "describe",
  "gives_whole_targets",
  "length_options",
  "load",
  "on_register",
  "register",
  "tracking_task",
]
