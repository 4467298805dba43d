"""The suite's tasks by name, in the order they were registered: one ``TaskEntry`` each.

``softbench.suite`` reads it (``TASKS``, ``ALL_TASKS``, ``BENCHMARKING``, ``describe``, ``load``).
``register`` adds any task; ``suite.tracking_task`` adds a tracking task from the one function
that traces its reference (``softbench/suite/shapes.py`` holds the built-in ones).
"""

import dataclasses
from typing import TYPE_CHECKING
from typing import Any
from typing import Callable

from softbench import registries
from softbench import robots

if TYPE_CHECKING:
  from softbench.suite import references


@dataclasses.dataclass(frozen=True, kw_only=True)
class TaskEntry:
  """A task of the suite, as ``register`` takes it (Gymnasium's ``EnvSpec`` for the suite).

  Attributes:
    build: ``build(robot, random=..., **options)`` returns the task (a ``base.SoftArmTask``); its
      other keyword arguments are the task's options (``suite.load(..., **options)``).
    tags: ``benchmarking`` puts the task on the leaderboard's grid and in ``BENCHMARKING``;
      ``tracking`` with it, in the leaderboard's aggregate across tasks; ``user``, out of
      ``ALL_TASKS`` (it needs the user's input).
    description: one line, as ``softbench tasks`` lists it.
    paper_robot: the robot the task runs on in the paper, the default of ``softbench run --robot``.
    length_option: the option that sets its episode length in control steps (None: the user's
      trajectory does).
    partial_targets: ``partial_targets(robot, options)``, whether its targets leave part of the
      arm's pose out (None: they never do).
    reference: the shape its reference is traced from (tracking tasks of ``suite.tracking_task``),
      else None.
  """

  build: Callable[..., Any]
  tags: tuple[str, ...]
  description: str
  paper_robot: str
  length_option: str | None
  partial_targets: Callable[..., bool] | None = None
  reference: "references.Shape | None" = None


_TASKS: dict[str, TaskEntry] = {}
_LISTENERS: list[Callable[[str], None]] = []  # Called with each task registered later.


def register(name: str, entry: TaskEntry) -> None:
  """Adds task ``name`` to the suite.

  Raises:
    ValueError: the name is taken or malformed, or the paper robot is unknown (one line).
  """
  registries.check_new_name("task", name, _TASKS)
  if not isinstance(entry, TaskEntry):
    raise ValueError(f"task {name!r}: a TaskEntry is needed, got {type(entry).__name__}")
  robots.make(entry.paper_robot)
  _TASKS[name] = entry
  for listener in _LISTENERS:
    listener(name)


def on_register(listener: Callable[[str], None]) -> None:
  """Calls ``listener(name)`` for every task that ``register`` adds from now on (so that
  ``softbench.envs`` gives it Gymnasium ids, whichever of the two is imported first)."""
  _LISTENERS.append(listener)


def names() -> tuple[str, ...]:
  """Every registered task, in registration order."""
  return tuple(_TASKS)


def describe(task: str) -> TaskEntry:
  """The entry of ``task``.

  Raises:
    ValueError: the task is not registered (one line).
  """
  if task not in _TASKS:
    raise ValueError(f"unknown task {task!r}; choose one of {', '.join(_TASKS)}")
  return _TASKS[task]


def pairs(tag: str | None = None) -> tuple[tuple[str, str], ...]:
  """Every (registered robot, task) pair of the tasks that need no user input (not tagged
  ``user``), or only of those tagged ``tag``."""
  return tuple(
    (robot, task)
    for robot in robots.REGISTERED_ROBOTS
    for task, entry in _TASKS.items()
    if "user" not in entry.tags and (tag is None or tag in entry.tags)
  )
