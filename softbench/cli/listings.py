"""What ``softbench robots``, ``tasks``, ``agents`` and ``streams`` list: a table for people
(``*_table``) and a JSON document for scripts (``*_document``, their ``--json``), from the
registries alone (without torch)."""

from rich.console import Group
from rich.console import RenderableType

from softbench import agents
from softbench import robots
from softbench import suite
from softbench import terminal
from softbench.agents import hyperparameters
from softbench.continual import strategies
from softbench.continual import streams
from softbench.robots import export as model_export

_ROBOT_COLUMNS = ("robot", "modules", "action dim", "length mm", "mass g")


def robot_facts(robot: robots.SoftArm) -> dict:
  """What ``softbench robots --json`` tells of ``robot`` (SI units)."""
  return {
    "name": robot.name,
    "modules": robot.num_modules,
    "action_dim": robot.action_dim,
    "actuators_per_module": list(robot.actuators_per_module),
    "length_m": robot.length,
    "mass_kg": robot.mass(),
    "control_period_s": robot.control_timestep,
  }


def robots_document(name: str | None = None, **overrides) -> list[dict] | dict:
  """The facts of every registered robot, or of robot ``name`` with its spec; ``overrides`` change
  the spec (``robots.make``)."""
  if name is None:
    return [robot_facts(robots.make(listed, **overrides)) for listed in robots.REGISTERED_ROBOTS]
  robot = robots.make(name, **overrides)
  return {**robot_facts(robot), "spec": dict(model_export.spec_fields(robot))}


def robots_table(name: str | None = None, **overrides) -> RenderableType:
  """Every registered robot, one row each; or robot ``name``'s row, control period and spec."""
  if name is None:
    return Group(
      _robot_rows([robots.make(listed, **overrides) for listed in robots.REGISTERED_ROBOTS]),
      "",
      f"{len(robots.REGISTERED_ROBOTS)} registered robots (any tendon arm of 1 to 10 modules "
      f"also builds); the leaderboard ranks agents on {', '.join(robots.LEADERBOARD_ROBOTS)}",
    )
  robot = robots.make(name, **overrides)
  return Group(
    _robot_rows([robot]),
    "",
    f"control period: {robot.control_timestep} s; actions per module: "
    f"{', '.join(map(str, robot.actuators_per_module))}",
    *(f"  {field} = {value}" for field, value in model_export.spec_fields(robot)),
  )


def _robot_rows(listed: list[robots.SoftArm]) -> RenderableType:
  rows = [
    [
      robot.name,
      str(robot.num_modules),
      str(robot.action_dim),
      f"{robot.length * 1000:.0f}",
      f"{robot.mass() * 1000:.1f}",
    ]
    for robot in listed
  ]
  return terminal.table(_ROBOT_COLUMNS, rows, right=_ROBOT_COLUMNS[1:])


def tasks_document() -> list[dict]:
  """Every task: its tags, description and the registered robots it is scored on."""
  return [
    {
      "name": task,
      "tags": list(suite.describe(task).tags),
      "description": suite.describe(task).description,
      "registered_robots": [robot for robot, name in suite.ALL_TASKS if name == task],
    }
    for task in suite.TASKS
  ]


def tasks_table() -> RenderableType:
  """Every task with its tags and description, then the control periods and the pairs."""
  rows = [
    [task, ", ".join(suite.describe(task).tags), suite.describe(task).description]
    for task in suite.TASKS
  ]
  periods = sorted(
    {(robots.make(name).control_timestep, name.split("-")[0]) for name in robots.REGISTERED_ROBOTS},
    key=lambda item: item[1],
  )
  return Group(
    terminal.table(("task", "tags", "description"), rows),
    "",
    "control period: "
    + "; ".join(f"{family} arms {period:g} s ({1 / period:g} Hz)" for period, family in periods),
    f"{len(suite.ALL_TASKS)} (robot, task) pairs on the registered robots "
    f"({', '.join(robots.REGISTERED_ROBOTS)}); every task runs on any robot; the leaderboard "
    f"scores the benchmarking tasks on {', '.join(robots.LEADERBOARD_ROBOTS)}",
  )


def agents_document() -> list[dict]:
  """Every agent: whether it learns, its description and its hyperparameters per robot."""
  tuned = hyperparameters.load()["agents"]
  return [
    {
      "name": name,
      "learned": agents.describe(name).learned,
      "description": agents.describe(name).description,
      "hyperparameters": {robot: values["params"] for robot, values in tuned.get(name, {}).items()},
    }
    for name in agents.AGENTS
  ]


def agents_table(verbose: bool = False) -> RenderableType:
  """Every agent, whether it learns and its description; ``verbose``: under each learned agent,
  its hyperparameters per robot and where they come from."""
  tuned = hyperparameters.load()["agents"] if verbose else {}
  rows = []
  for name in agents.AGENTS:
    entry = agents.describe(name)
    rows.append([name, "yes" if entry.learned else "no", entry.description])
    if entry.learned:
      rows += [
        ["", "", f"{robot}: {hyperparameters.describe_entry(values)}"]
        for robot, values in tuned.get(name, {}).items()
      ]
  return terminal.table(("agent", "learns", "description"), rows)


def streams_document(family: str = streams.DEFAULT_FAMILY) -> dict:
  """Every continual stream (its configurations on ``family``) and every continual strategy."""
  return {
    "streams": [
      {
        "name": name,
        "description": streams.get(name).description,
        "task": streams.get(name).task,
        "configurations": [c.describe() for c in streams.get(name).configurations(family)],
      }
      for name in streams.STREAMS
    ],
    "strategies": [
      {"name": name, "description": strategies.describe(name).description}
      for name in strategies.STRATEGIES
    ],
  }


def streams_table(family: str = streams.DEFAULT_FAMILY) -> RenderableType:
  """The streams with their configurations on ``family``, then the strategies."""
  listed = streams_document(family)
  stream_rows = [
    [entry["name"], ", ".join(c["label"] for c in entry["configurations"]), entry["description"]]
    for entry in listed["streams"]
  ]
  strategy_rows = [[entry["name"], entry["description"]] for entry in listed["strategies"]]
  return Group(
    terminal.table(("stream", f"configurations ({family})", "what changes"), stream_rows),
    "",
    terminal.table(("strategy", "description"), strategy_rows),
    "",
    "softbench run --protocol continual --stream STREAM --agent STRATEGY; docs/continual.md",
  )
