"""Each agent across the tracking tasks, the way rliable aggregates (Agarwal et al., "Deep RL at
the Edge of the Statistical Precipice", NeurIPS 2021): the interquartile mean (IQM) of its runs'
normalised tip error, with a stratified bootstrap interval, and the performance profile.

A run is one seed on one task, every task counting alike; the normalised tip error (% of the
arm's length) puts tasks on one scale. Per robot, profile and eval mode, the view's tasks are the
registered benchmark tracking tasks (``tasks()``) that some agent has a record of, at least
``MIN_TASKS``, and each agent is aggregated over them from the newest record of each. An agent
that lacks one of them is shown with the missing tasks named in place of its IQM, after the
others (an IQM over other tasks would not compare); a view needs one agent with every task. The
stratified bootstrap resamples the seeds within each task (``BOOTSTRAP_RESAMPLES`` times,
seeded), so every resample keeps the task mix.
"""

import dataclasses

import numpy as np
from scipy import stats

from softbench import agents
from softbench import plots
from softbench import suite
from softbench.leaderboard import figure_table
from softbench.leaderboard import ranking

MIN_TASKS = 2  # Tasks a view aggregates at least: over one, it is that task's own table.
METRIC = "normalised_tip_percent"
TRIMMED = 0.25  # Share cut from each end: the interquartile mean.
BOOTSTRAP_RESAMPLES = 2_000
BOOTSTRAP_SEED = 0  # Fixed: regenerating the pages gives the same intervals.
PROFILE_THRESHOLDS = np.logspace(-4, 2, 61)  # (% of the arm's length) Of performance profiles.


def tasks() -> tuple[str, ...]:
  """The benchmark's tracking tasks, as registered now (reach scores one module)."""
  return tuple(
    task for task in suite.TASKS if {"benchmarking", "tracking"} <= set(suite.describe(task).tags)
  )


def iqm(runs: list[np.ndarray]) -> float:
  """The interquartile mean of every run of every task (``runs``: one array per task)."""
  return float(stats.trim_mean(np.concatenate(runs), TRIMMED))


def stratified_interval(
  runs: list[np.ndarray], resamples: int = BOOTSTRAP_RESAMPLES
) -> tuple[float, float]:
  """The ``ranking.CONFIDENCE`` percentile interval of the IQM over ``resamples`` resamples that
  draw, within each task, as many runs as it has, with replacement."""
  rng = np.random.default_rng(BOOTSTRAP_SEED)
  draws = [task[rng.integers(0, len(task), (resamples, len(task)))] for task in runs]
  values = stats.trim_mean(np.concatenate(draws, axis=1), TRIMMED, axis=1)
  tail = (1 - ranking.CONFIDENCE) / 2 * 100
  low, high = np.percentile(values, [tail, 100 - tail])
  return float(low), float(high)


def performance_profile(runs: list[np.ndarray], thresholds=PROFILE_THRESHOLDS) -> np.ndarray:
  """The share of runs whose error is at most each threshold (every task weighs alike)."""
  return np.mean([(task[:, None] <= thresholds).mean(axis=0) for task in runs], axis=0)


@dataclasses.dataclass(frozen=True)
class Aggregate:
  """One agent's runs over a view's tasks on one robot, profile and eval mode, with their IQM and
  its interval (``of`` computes both once), or, if it lacks a task, the tasks it lacks."""

  agent: str
  runs: tuple[np.ndarray, ...]  # One array of per-seed errors per task it has, in view order.
  iqm: float | None  # None where tasks are missing.
  interval: tuple[float, float] | None
  missing: tuple[str, ...] = ()  # The view's tasks it has no record of.

  @classmethod
  def of(cls, agent: str, by_task: dict[str, np.ndarray], tasks: tuple[str, ...]) -> "Aggregate":
    """The aggregate of ``agent``'s per-seed errors ``by_task`` over ``tasks``."""
    runs = tuple(by_task[task] for task in tasks if task in by_task)
    missing = tuple(task for task in tasks if task not in by_task)
    if missing:
      return cls(agent, runs, None, None, missing)
    return cls(agent, runs, iqm(list(runs)), stratified_interval(list(runs)))

  @property
  def missing_text(self) -> str:
    """The text of its IQM cell when it lacks tasks."""
    return f"- (no {', '.join(self.missing)})"


@dataclasses.dataclass(frozen=True)
class View:
  """The aggregates of one robot, profile and eval mode over ``tasks``, best IQM first, then the
  agents that lack one of them."""

  robot: str
  profile: str
  eval_mode: str
  aggregates: tuple[Aggregate, ...]
  tasks: tuple[str, ...]  # Those of ``tasks()`` that some agent here has a record of.

  @property
  def title(self) -> str:
    return f"{self.robot} across tasks · {self.profile} profile · {self.eval_mode}"

  @property
  def anchor(self) -> str:
    return f"across-tasks-{self.robot}-{self.profile}-{self.eval_mode}"

  @property
  def image(self) -> str:
    """The file name of its performance-profile plot, beside the pages."""
    return f"{self.anchor}.png"

  @property
  def complete(self) -> tuple[Aggregate, ...]:
    """The aggregates of the agents with every task, which have an IQM."""
    return tuple(found for found in self.aggregates if not found.missing)

  def write_profiles(self, folder) -> None:
    """Saves the performance profiles of its agents with every task as ``folder / image``."""
    curves = {found.agent: performance_profile(list(found.runs)) for found in self.complete}
    plots.performance_profiles(
      curves, PROFILE_THRESHOLDS, f"{self.title}: performance profiles", folder / self.image
    )

  @property
  def table(self) -> figure_table.Table:
    rows = []
    for found in self.aggregates:
      runs = str(sum(len(task) for task in found.runs))
      if found.missing:
        rows.append((found.agent, runs, found.missing_text, "-", "-"))
        continue
      low, high = found.interval
      rows.append(
        (
          found.agent,
          runs,
          ranking.number(found.iqm),
          f"[{ranking.number(low)}, {ranking.number(high)}]",
          ranking.number(float(np.median(np.concatenate(found.runs)))),
        )
      )
    caption = (
      f"normalised tip error (% of the arm's length) over {', '.join(self.tasks)}, a run being "
      f"one seed on one task: interquartile mean (IQM), its {ranking.CONFIDENCE:.0%} stratified "
      f"bootstrap interval ({BOOTSTRAP_RESAMPLES:,} resamples) and the median; lower is better"
    )
    if len(self.complete) < len(self.aggregates):
      caption += "; - (no TASK): no record of TASK, so no IQM that compares"
    unrun = [task for task in tasks() if task not in self.tasks]
    if unrun:
      caption += f"; no record yet of {', '.join(unrun)}"
    header = ("agent", "runs", "IQM", "interval", "median")
    return figure_table.Table(caption, header, tuple(rows), label_columns=2)


def views(board: ranking.Leaderboard) -> tuple[View, ...]:
  """Every robot, profile and eval mode where some agent has records of at least ``MIN_TASKS``
  of ``tasks()``, and of every one that another agent there has."""
  aggregated = tasks()
  runs: dict[tuple[str, str, str], dict[str, dict[str, np.ndarray]]] = {}
  for group, entry in ranking.plain_entries(board):
    agent, profile, eval_mode = entry.setting
    if group.task in aggregated and METRIC in entry.estimates:
      per_seed = np.array([seed[METRIC]["mean"] for seed in entry.record["per_seed"]])
      runs.setdefault((group.robot, profile, eval_mode), {}).setdefault(agent, {})[group.task] = (
        per_seed
      )
  found = []
  for (robot, profile, eval_mode), by_agent in runs.items():
    recorded = tuple(
      task for task in aggregated if any(task in by_task for by_task in by_agent.values())
    )
    shown = [Aggregate.of(agent, by_task, recorded) for agent, by_task in by_agent.items()]
    if len(recorded) < MIN_TASKS or all(item.missing for item in shown):
      continue
    shown.sort(
      key=lambda item: (
        bool(item.missing),
        item.iqm if item.iqm is not None else 0.0,
        ranking.known_first(item.agent, agents.AGENTS),
      )
    )
    found.append(View(robot, profile, eval_mode, tuple(shown), recorded))
  found.sort(key=lambda view: ranking.setting_order(view.robot, view.profile, view.eval_mode))
  return tuple(found)
