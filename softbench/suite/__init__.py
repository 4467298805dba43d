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

Importing the suite loads no simulator: the task list and each task's entry (``describe``) come
without dm_control or MuJoCo, which ``load`` and ``build_task`` (``loading``) import on first use.

One control step lasts the robot's control period (``robot.control_timestep``): 1 s for the
tendon arms (1 Hz, the paper's simulator; tendon-5, the slowest, settles in 0.72 s) and 0.2 s
for the pneumatic arm (5 Hz, as on the real robot).
"""

import lazy_loader

from softbench.suite import registry
from softbench.suite import shapes  # noqa: F401  Registers babbling, circle, rectangle, spiral.

TaskEntry = registry.TaskEntry
describe = registry.describe
on_register = registry.on_register
register = registry.register
tracking_task = registry.tracking_task

# After the tracking shapes (the import of ``shapes``), in the order the tables list tasks.
register(
  "reach",
  TaskEntry(
    build="softbench.suite.reach:Reach",
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
    build="softbench.suite.tracking:custom",
    tags=("tracking", "user"),
    description="follow your own trajectory (.npy or .csv, one target per row)",
    paper_robot="tendon-3",
    length_option=None,
    partial_targets="softbench.suite.trajectories:leaves_part_out",
  ),
)

_LISTS = {
  "TASKS": registry.names,
  "ALL_TASKS": registry.pairs,
  "BENCHMARKING": lambda: registry.pairs("benchmarking"),
}
_load_on_use, __dir__, _LOADED_ON_USE = lazy_loader.attach(
  __name__,
  submodules=["base", "loading", "reach", "references", "tracking", "trajectories"],
  submod_attrs={"loading": ["build_task", "gives_whole_targets", "load"]},
)


def __getattr__(name: str):
  """``TASKS`` (every task's name), ``ALL_TASKS`` and ``BENCHMARKING``, as registered now; and
  ``load``, ``build_task`` and ``gives_whole_targets``, imported on first use."""
  if name in _LISTS:
    return _LISTS[name]()
  return _load_on_use(name)


def length_options(task: str, steps: int | None) -> dict:
  """The options of ``load`` that make ``task``'s episodes ``steps`` control steps long ({} for
  None, or for ``custom``, whose trajectory sets its length)."""
  option = describe(task).length_option
  return {} if steps is None or option is None else {option: steps}


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
