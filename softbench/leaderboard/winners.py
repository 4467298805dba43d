"""Who is best on what: the first thing the leaderboard's pages show.

For every overview (a robot, profile and eval mode; ``overview.overviews``) and task, the best
learned agent (lowest mean position error over seeds; ``agents.is_learned``, oracles excluded)
and, apart, the oracles' figure (``agents.is_oracle``: agents that use the simulator itself, a
bound rather than a competitor). The sanity baselines (``zero``, ``random``) never win.
"""

import dataclasses

from softbench import agents
from softbench import suite
from softbench.leaderboard import overview
from softbench.leaderboard import ranking


@dataclasses.dataclass(frozen=True)
class Best:
  """The best learned agent on one task of an overview, and the oracles' figures there."""

  task: str
  agent: str | None  # None: no learned agent has a record of the task yet.
  estimate: ranking.Estimate | None
  mark: str  # The completion mark of its figure (``ranking.COMPLETED_MARK``), or "".
  oracles: tuple[tuple[str, ranking.Estimate], ...]

  @property
  def figure(self) -> str:
    return "-" if self.estimate is None else ranking.mean_and_std(self.estimate) + self.mark


@dataclasses.dataclass(frozen=True)
class Row:
  """One overview's winners, task by task."""

  view: overview.Overview
  best: tuple[Best, ...]


def _best(view: overview.Overview, task: str) -> Best:
  found = [
    (agent, estimate) for (agent, shown), estimate in view.estimates.items() if shown == task
  ]
  learned = [
    (estimate.mean, agent, estimate)
    for agent, estimate in found
    if agents.is_learned(agent) and not agents.is_oracle(agent)
  ]
  oracles = tuple(sorted((agent, est) for agent, est in found if agents.is_oracle(agent)))
  if not learned:
    return Best(task, None, None, "", oracles)
  _, agent, estimate = min(learned)
  return Best(task, agent, estimate, view.marks.get((agent, task), ""), oracles)


def tasks(views: tuple[overview.Overview, ...]) -> tuple[str, ...]:
  """The tasks any of ``views`` holds, in the suite's order."""
  found = {task for view in views for task in view.table.header[1:]}
  return tuple(sorted(found, key=suite.TASKS.index))


def rows(views: tuple[overview.Overview, ...]) -> tuple[Row, ...]:
  """Each overview's winners on every task of ``tasks(views)``."""
  shown = tasks(views)
  return tuple(Row(view, tuple(_best(view, task) for task in shown)) for view in views)


def best_cells(view: overview.Overview) -> set[tuple[str, str]]:
  """The (agent, task) cells of ``view`` that hold a task's best learned agent."""
  return {
    (best.agent, best.task)
    for best in (_best(view, task) for task in view.table.header[1:])
    if best.agent is not None
  }
