"""Part of the leaderboard: the records of some robots, tasks, agents, profiles or physics versions
(``softbench leaderboard --robots ... --tasks ... --agents ... --profiles ... --physics ...``)."""

import dataclasses

from softbench import agents as agent_registry
from softbench import profiles as profile_registry
from softbench import records
from softbench import robots as robot_registry
from softbench import suite
from softbench.records import exp1s as exp1s_records
from softbench.records import fields as record_fields
from softbench.robots import versions


@dataclasses.dataclass(frozen=True)
class RecordFilter:
  """The records to show: on any of ``robots``, of any of ``tasks``, by any of ``agents``, at any
  of ``profiles``, simulated with any of the ``physics`` versions; an empty tuple keeps every one.
  An Exp1S record, which trains on several arms and has no task of its own, is kept when none of
  its arms is left out and no task is asked for."""

  robots: tuple[str, ...] = ()
  tasks: tuple[str, ...] = ()
  agents: tuple[str, ...] = ()
  profiles: tuple[str, ...] = ()
  physics: tuple[str, ...] = ()

  def __post_init__(self) -> None:
    """Checks every name against its registry.

    Raises:
      ValueError: an unknown robot, task, agent, profile or physics version (one line).
    """
    for robot in self.robots:
      robot_registry.checked_family(robot)
    for task in self.tasks:
      if task not in suite.TASKS:
        raise ValueError(f"unknown task {task!r}; choose from {', '.join(suite.TASKS)}")
    for agent in self.agents:
      agent_registry.describe(agent)
    for profile in self.profiles:
      profile_registry.get(profile)
    for name in self.physics:
      versions.named(name)

  @property
  def active(self) -> bool:
    return any((self.robots, self.tasks, self.agents, self.profiles, self.physics))

  def keeps(self, record: dict) -> bool:
    if self.physics and record_fields.physics_of(record) not in self.physics:
      return False
    if self.agents and record["agent"] not in self.agents:
      return False
    if self.profiles and record["profile"] not in self.profiles:
      return False
    if record["format"] == exp1s_records.FORMAT:
      return not self.tasks and (not self.robots or set(record["robots"]) <= set(self.robots))
    if record["format"] != records.FORMAT:
      return not self.active
    return (not self.robots or record["robot"] in self.robots) and (
      not self.tasks or record["task"] in self.tasks
    )

  def describe(self) -> str:
    """``robots tendon-3, tasks reach`` (what is asked for), for the printout's first line."""
    return ", ".join(
      f"{axis} {', '.join(names)}" for axis, names in dataclasses.asdict(self).items() if names
    )
