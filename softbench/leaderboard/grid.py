"""The settings the leaderboard is filled with (``make leaderboard``): every registered agent on
every benchmarking task of ``ROBOTS``, then Exp1S on every tendon family."""

from softbench import agents
from softbench import robots
from softbench import suite

ROBOTS = robots.LEADERBOARD_ROBOTS


def lists() -> dict[str, tuple[str, ...]]:
  """The grid's axes by name: robots, tasks, agents and Exp1S families."""
  return {
    "robots": ROBOTS,
    "tasks": tuple(task for task in suite.TASKS if "benchmarking" in suite.describe(task).tags),
    "agents": agents.AGENTS,
    "families": tuple(robots.TENDON_FAMILY_NAMES),
  }
