"""The suite's tasks by name, in the order they were registered: one ``TaskEntry`` each.

``softbench.suite`` reads it (``TASKS``, ``ALL_TASKS``, ``BENCHMARKING``, ``describe``, ``load``).
``register`` adds any task; ``tracking_task`` adds a tracking task from the one function that
traces its reference (``softbench/suite/shapes.py`` holds the built-in ones).

Registering loads no simulator: an entry may name its builder by import path (``module:name``,
as Gymnasium's ``entry_point``), which is imported when the task is first built, so that the
records and the leaderboard read the task list without MuJoCo or dm_control.
"""

import dataclasses
import importlib
import inspect
import json
from typing import TYPE_CHECKING
from typing import Any
from typing import Callable

import numpy as np

from softbench import registries
from softbench import robots

if TYPE_CHECKING:
  from softbench.robots.base import SoftArm

REFERENCE_LENGTH = 1000  # Target poses per reference (paper: 1,000 samples per trajectory).
INITIAL_ACTUATION = 0.2  # Largest |action| entry of the random actuation held before an episode.
_FIXED_ARGUMENTS = {True: ("length",), False: ("robot", "length")}  # Of a planar shape, of others.


@dataclasses.dataclass(frozen=True, kw_only=True)
class TaskEntry:
  """A task of the suite, as ``register`` takes it (Gymnasium's ``EnvSpec`` for the suite).

  Attributes:
    build: ``build(robot, random=..., **options)`` returns the task (a ``base.SoftArmTask``); its
      other keyword arguments are the task's options (``suite.load(..., **options)``). A callable,
      or its import path ``module:name``, imported on first use (``builder``).
    tags: ``benchmarking`` puts the task on the leaderboard's grid and in ``BENCHMARKING``;
      ``tracking`` with it, in the leaderboard's aggregate across tasks; ``user``, out of
      ``ALL_TASKS`` (it needs the user's input).
    description: one line, as ``softbench tasks`` lists it.
    paper_robot: the robot the task runs on in the paper, the default of ``softbench run --robot``.
    length_option: the option that sets its episode length in control steps (None: the user's
      trajectory does).
    partial_targets: ``partial_targets(robot, options)``, whether its targets leave part of the
      arm's pose out (None: they never do); a callable or its import path, as ``build``.
    reference: the shape its reference is traced from (tracking tasks of ``tracking_task``),
      else None.
  """

  build: Callable[..., Any] | str
  tags: tuple[str, ...]
  description: str
  paper_robot: str
  length_option: str | None
  partial_targets: Callable[..., bool] | str | None = None
  reference: "Shape | None" = None

  def builder(self) -> Callable[..., Any]:
    """``build``, imported if it is a path."""
    return _resolved(self.build)

  def leaves_part_out(self, robot: "SoftArm", options: dict) -> bool:
    """Whether the task's targets (with ``options``) leave part of ``robot``'s pose out."""
    return self.partial_targets is not None and _resolved(self.partial_targets)(robot, options)


def _resolved(target: Callable | str) -> Callable:
  """``target``, or the object that its path ``module:name`` names.

  Raises:
    ValueError: the path names nothing that can be imported (one line).
  """
  if callable(target):
    return target
  module, _, name = target.partition(":")
  try:
    return getattr(importlib.import_module(module), name)
  except (ImportError, AttributeError) as error:
    raise ValueError(f"{target!r} cannot be imported ({type(error).__name__}: {error})") from None


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
  for field in ("build", "partial_targets"):
    value = getattr(entry, field)
    if isinstance(value, str) and (":" not in value or not all(value.partition(":")[::2])):
      raise ValueError(f"task {name!r}: {field} paths are module:name, got {value!r}")
  robots.checked_family(entry.paper_robot)
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


def tracking_task(
  description: str,
  *,
  tags: tuple[str, ...] = ("benchmarking",),
  paper_robot: str = "tendon-3",
  planar: bool = True,
) -> Callable[[Callable], Callable]:
  """Registers the decorated function as the tracking task of its name: every module follows the
  poses the robot reaches when the function's actions drive it from rest (its reference,
  ``Shape``), one target per control step for ``length`` steps (``load``'s option, default
  ``REFERENCE_LENGTH``).

  The function is ``trace(length, **parameters)``, returning (length, 2) points of the planar
  actuation space in bend amplitudes (every module bent alike), or, with ``planar=False``,
  ``trace(robot, length, **parameters)`` returning the robot's actions (length, action_dim) in
  [-1, 1]. Each parameter needs a default (numbers, strings or lists of them): the cache key of
  the task's references hashes them, and no other task's. The task's tags are ``tags`` and
  ``tracking``; the function is returned unchanged.

  Raises:
    ValueError: the name is taken or malformed, the arguments are not as above, or the paper
      robot is unknown (one line).
  """

  def register_shape(trace: Callable) -> Callable:
    shape = Shape(trace.__name__, trace, planar)
    register(
      shape.name,
      TaskEntry(
        build=_following(shape.name),
        tags=tuple(dict.fromkeys((*tags, "tracking"))),
        description=description,
        paper_robot=paper_robot,
        length_option="length",
        reference=shape,
      ),
    )
    return trace

  return register_shape


def _following(shape: str) -> Callable[..., Any]:
  """The task that follows reference ``shape`` (``TaskEntry.build``; ``tracking.Tracking``)."""

  def build(
    robot: "SoftArm",
    length: int = REFERENCE_LENGTH,
    initial_actuation: float = INITIAL_ACTUATION,
    random=None,
  ):
    from softbench.suite import tracking  # Loads dm_control when a task is built, not registered.

    return tracking.following(robot, shape, length, initial_actuation, random)

  return build


@dataclasses.dataclass(frozen=True)
class Shape:
  """How a tracking task's reference is traced: ``trace(length, **parameters)`` gives (length, 2)
  points of the planar actuation space in bend amplitudes (``planar``), else
  ``trace(robot, length, **parameters)`` gives the robot's actions (length, action_dim) in
  [-1, 1]. Its parameters are the defaults of its other arguments (numbers, strings, or lists
  and tuples of them): the cache key of its references hashes them, and no other shape's."""

  name: str
  trace: Callable[..., np.ndarray]
  planar: bool = True

  def __post_init__(self):
    arguments = list(inspect.signature(self.trace).parameters.values())
    fixed = _FIXED_ARGUMENTS[self.planar]
    if tuple(argument.name for argument in arguments[: len(fixed)]) != fixed:
      raise ValueError(
        f"shape {self.name!r}: {self.trace.__name__} must take ({', '.join(fixed)}, ...) first"
      )
    for argument in arguments[len(fixed) :]:
      if argument.default is inspect.Parameter.empty:
        raise ValueError(f"shape {self.name!r}: parameter {argument.name!r} needs a default")
    try:
      json.dumps(self.parameters, allow_nan=False)
    except (TypeError, ValueError) as error:
      raise ValueError(
        f"shape {self.name!r}: parameters must be numbers, strings or lists of them ({error})"
      ) from None

  @property
  def parameters(self) -> dict:
    """The defaults of ``trace``'s arguments after the robot and the length, by name."""
    arguments = list(inspect.signature(self.trace).parameters.values())
    return {
      argument.name: argument.default
      for argument in arguments[len(_FIXED_ARGUMENTS[self.planar]) :]
    }

  def actions(self, robot: "SoftArm", length: int, amplitude: float | None) -> np.ndarray:
    """The actions (length, action_dim) that trace the shape on ``robot``; a planar shape's
    points are scaled by ``amplitude`` (``references.bend_amplitude(robot)`` for the task's
    references).

    Raises:
      ValueError: ``trace`` gave an array of another shape, values that are not finite, or
        actions out of [-1, 1] (one line).
    """
    if not self.planar:
      actions = self._checked(self.trace(robot, length), (length, robot.action_dim))
      if np.any(np.abs(actions) > 1.0):
        raise ValueError(f"shape {self.name!r} gave actions out of [-1, 1]")
      return actions
    points = self._checked(self.trace(length), (length, 2))
    return robot.planar_action(amplitude * points)

  def _checked(self, traced, expected: tuple[int, ...]) -> np.ndarray:
    traced = np.asarray(traced, dtype=float)
    if traced.shape != expected:
      raise ValueError(f"shape {self.name!r} gave an array {traced.shape}, not {expected}")
    if not np.all(np.isfinite(traced)):
      raise ValueError(f"shape {self.name!r} gave NaN or infinite values")
    return traced
