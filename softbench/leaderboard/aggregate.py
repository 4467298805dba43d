"""Each agent across the tracking tasks, the way rliable aggregates (Agarwal et al., "Deep RL at
the Edge of the Statistical Precipice", NeurIPS 2021): the interquartile mean (IQM) of its runs'
normalised tip error, with a stratified bootstrap interval, and the performance profile.

A run is one seed on one task, every task counting alike; the normalised tip error (% of the
arm's length) puts tasks on one scale. Per robot, profile and eval mode, an agent is aggregated
over ``TASKS`` from the newest record of each; an agent that lacks one of them is left out (an
IQM over other tasks would not compare). The stratified bootstrap resamples the seeds within
each task (``BOOTSTRAP_RESAMPLES`` times, seeded), so every resample keeps the task mix.
"""

import dataclasses

import numpy as np
from scipy import stats

from softbench import agents
from softbench import plots
from softbench import suite
from softbench.leaderboard import figure_table
from softbench.leaderboard import ranking

TASKS = tuple(
  task for task in suite.TASKS if {"benchmarking", "tracking"} <= set(suite.describe(task).tags)
)  # The benchmark's tracking tasks (reach scores one module).
METRIC = "normalised_tip_percent"
TRIMMED = 0.25  # Share cut from each end: the interquartile mean.
BOOTSTRAP_RESAMPLES = 2_000
BOOTSTRAP_SEED = 0  # Fixed: regenerating the pages gives the same intervals.
PROFILE_THRESHOLDS = np.logspace(-4, 2, 61)  # (% of the arm's length) Of performance profiles.


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
  """One agent's runs over ``TASKS`` on one robot, profile and eval mode, with their IQM and its
  interval (``of`` computes both once)."""

  agent: str
  runs: tuple[np.ndarray, ...]  # One array of per-seed errors per task, in ``TASKS`` order.
  iqm: float
  interval: tuple[float, float]

  @classmethod
  def of(cls, agent: str, runs: tuple[np.ndarray, ...]) -> "Aggregate":
    return cls(agent, runs, iqm(list(runs)), stratified_interval(list(runs)))


@dataclasses.dataclass(frozen=True)
class View:
  """The aggregates of one robot, profile and eval mode, best IQM first."""

  robot: str
  profile: str
  eval_mode: str
  aggregates: tuple[Aggregate, ...]

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

  def write_profiles(self, folder) -> None:
    """Saves the performance profiles of its agents as ``folder / image``."""
    curves = {found.agent: performance_profile(list(found.runs)) for found in self.aggregates}
    plots.performance_profiles(
      curves, PROFILE_THRESHOLDS, f"{self.title}: performance profiles", folder / self.image
    )

  @property
  def table(self) -> figure_table.Table:
    rows = []
    for found in self.aggregates:
      low, high = found.interval
      runs = sum(len(task) for task in found.runs)
      rows.append(
        (
          found.agent,
          str(runs),
          ranking.number(found.iqm),
          f"[{ranking.number(low)}, {ranking.number(high)}]",
          ranking.number(float(np.median(np.concatenate(found.runs)))),
        )
      )
    caption = (
      f"normalised tip error (% of the arm's length) over {', '.join(TASKS)}, a run being one "
      f"seed on one task: interquartile mean (IQM), its {ranking.CONFIDENCE:.0%} stratified "
      f"bootstrap interval ({BOOTSTRAP_RESAMPLES:,} resamples) and the median; lower is better"
    )
    header = ("agent", "runs", "IQM", "interval", "median")
    return figure_table.Table(caption, header, tuple(rows), label_columns=2)


def views(board: ranking.Leaderboard) -> tuple[View, ...]:
  """Every robot, profile and eval mode where an agent has records of all of ``TASKS``."""
  runs: dict[tuple[str, str, str], dict[str, dict[str, np.ndarray]]] = {}
  for group, entry in ranking.plain_entries(board):
    agent, profile, eval_mode = entry.setting
    if group.task in TASKS and METRIC in entry.estimates:
      per_seed = np.array([seed[METRIC]["mean"] for seed in entry.record["per_seed"]])
      runs.setdefault((group.robot, profile, eval_mode), {}).setdefault(agent, {})[group.task] = (
        per_seed
      )
  found = []
  for (robot, profile, eval_mode), by_agent in runs.items():
    complete = [
      Aggregate.of(agent, tuple(tasks[task] for task in TASKS))
      for agent, tasks in by_agent.items()
      if set(TASKS) <= set(tasks)
    ]
    if complete:
      complete.sort(key=lambda item: (item.iqm, ranking.known_first(item.agent, agents.AGENTS)))
      found.append(View(robot, profile, eval_mode, tuple(complete)))
  found.sort(key=lambda view: ranking.setting_order(view.robot, view.profile, view.eval_mode))
  return tuple(found)
