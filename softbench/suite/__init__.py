"""The softbench task suite, in the style of ``dm_control.suite``.

``load(robot, task, seed)`` returns a ``dm_control.rl.control.Environment``. Every task exists
for every robot; ``ALL_TASKS`` lists the (robot, task) pairs of the registered robots and
``BENCHMARKING`` those tagged ``benchmarking`` (dm_control's convention; so far every one).
``custom`` follows a user's trajectory (``trajectory=ARRAY_OR_PATH``; ``given="2:position"``
when it gives only part of the target, ``trajectories.Given``) and is in neither list, as it
needs one.

One control step lasts the robot's control period (``robot.control_timestep``): 1 s for the
tendon arms (1 Hz, the paper's simulator; tendon-5, the slowest, settles in 0.72 s) and 0.2 s
for the pneumatic arm (5 Hz, as on the real robot).
"""

import collections
import inspect
from typing import Callable

from dm_control.rl import control
import numpy as np

from softbench import robots
from softbench.data import seeding
from softbench.robots import physics as arm_physics
from softbench.suite import base
from softbench.suite import reach
from softbench.suite import references
from softbench.suite import tracking
from softbench.suite import trajectories

TaskEntry = collections.namedtuple(
  "TaskEntry",
  ["build", "tags", "description", "paper_robot", "length_option", "partial_targets"],
  defaults=(None,),
)
"""A task of the suite: ``build(robot, random=..., **options)``, its tags, a one-line description,
the robot it runs on in the paper (the default of ``softbench run --robot``), the option that
sets its episode length (None: the user's trajectory does) and ``partial_targets(robot,
options)``, whether its targets leave part of the arm's pose out (None: they never do)."""


def _reference_task(shape: str) -> Callable[..., base.SoftArmTask]:
  def build(
    robot,
    length: int = references.REFERENCE_LENGTH,
    initial_actuation: float = base.INITIAL_ACTUATION,
    random=None,
  ) -> base.SoftArmTask:
    return tracking.Tracking(
      robot,
      references.reference(robot, shape, length).targets,
      initial_actuation=initial_actuation,
      random=random,
    )

  return build


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


# The paper runs its Exp2S tracking on the tendon arm and its reaching on the pneumatic arm.
_TASKS = {
  "babbling": TaskEntry(
    _reference_task("babbling"),
    ("benchmarking", "tracking"),
    "follow held-out poses produced by random actuation",
    "tendon-3",
    "length",
  ),
  "circle": TaskEntry(
    _reference_task("circle"),
    ("benchmarking", "tracking"),
    "follow a circle traced in actuation space",
    "tendon-3",
    "length",
  ),
  "rectangle": TaskEntry(
    _reference_task("rectangle"),
    ("benchmarking", "tracking"),
    "follow a rectangle traced in actuation space",
    "tendon-3",
    "length",
  ),
  "spiral": TaskEntry(
    _reference_task("spiral"),
    ("benchmarking", "tracking"),
    "follow a growing spiral traced in actuation space",
    "tendon-3",
    "length",
  ),
  "reach": TaskEntry(
    reach.Reach,
    ("benchmarking",),
    "bring one module's tip to a virtual point (position only)",
    "pneumatic-433",
    "steps",
    lambda robot, options: True,
  ),
  "custom": TaskEntry(
    _custom_task,
    ("tracking", "user"),
    "follow your own trajectory (.npy or .csv, one target per row)",
    "tendon-3",
    None,
    lambda robot, options: (
      trajectories.as_given(options.get("given"), robot)
      not in (None, trajectories.Given.whole(robot))
    ),
  ),
}
TASKS = tuple(_TASKS)


def _pairs() -> tuple[tuple[tuple[str, str], ...], tuple[tuple[str, str], ...]]:
  """Every (robot, task) pair of the registered robots and the tasks that need no user input, and
  those of them tagged ``benchmarking``."""
  every = tuple(
    (robot, task)
    for robot in robots.REGISTERED_ROBOTS
    for task in TASKS
    if "user" not in _TASKS[task].tags
  )
  return every, tuple(pair for pair in every if "benchmarking" in _TASKS[pair[1]].tags)


ALL_TASKS, BENCHMARKING = _pairs()


_LISTENERS: list[Callable[[str], None]] = []  # Called with each task registered later.


def on_register(listener: Callable[[str], None]) -> None:
  """Calls ``listener(name)`` for every task that ``register`` adds from now on (so that
  ``softbench.envs`` gives it Gymnasium ids, whichever of the two is imported first)."""
  _LISTENERS.append(listener)


def register(name: str, entry: TaskEntry) -> None:
  """Adds task ``name`` to the suite (``TASKS``, ``ALL_TASKS`` and ``BENCHMARKING`` are rebound
  to include it): ``entry.build(robot, random=..., **options)`` returns a ``SoftArmTask``.

  Raises:
    ValueError: the name is taken or malformed, or the paper robot is unknown (one line).
  """
  global TASKS, ALL_TASKS, BENCHMARKING
  if not isinstance(name, str) or not name or name != name.strip().lower() or " " in name:
    raise ValueError(f"task names are lowercase words without spaces, got {name!r}")
  if name in _TASKS:
    raise ValueError(f"task {name!r} is registered already")
  robots.make(entry.paper_robot)
  _TASKS[name] = entry
  TASKS = tuple(_TASKS)
  ALL_TASKS, BENCHMARKING = _pairs()
  for listener in _LISTENERS:
    listener(name)


def describe(task: str) -> TaskEntry:
  if task not in _TASKS:
    raise ValueError(f"unknown task {task!r}; choose one of {', '.join(TASKS)}")
  return _TASKS[task]


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
  built = entry.build(arm.without_faults(), random=seed, **task_kwargs)
  physics = arm_physics.SoftArmPhysics.from_robot(arm)
  return control.Environment(
    physics, built, control_timestep=arm.control_timestep, **(environment_kwargs or {})
  )


__all__ = [
  "ALL_TASKS",
  "BENCHMARKING",
  "TASKS",
  "TaskEntry",
  "describe",
  "gives_whole_targets",
  "length_options",
  "load",
  "register",
]
