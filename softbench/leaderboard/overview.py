"""Overview tables: every agent on every task of a robot at a glance, beside the paper's values.

One table per robot, profile (paper first) and eval mode (physics first): agents by rows
(registry order, then any others by name), the tasks that have a record by columns (suite
order); the caption names the registered agents without a record there. A cell is the position
error (mm) of the row that the task's ranking shows for that agent, profile and eval mode (its
newest record): mean ± std over seeds of the episode's module-averaged error. Where the paper
reports the same robot, task and agent (``paper_exp2.json``: Exp2S for tendon-3, Exp2R for
pneumatic-433), the paper's mean follows in brackets. Only plain tasks count: a custom
trajectory, a fault or an extra section is a different experiment.
"""

import dataclasses

from softbench import agents
from softbench import suite
from softbench.leaderboard import paper_tables
from softbench.leaderboard import ranking
from softbench.leaderboard.figure_table import Table

PAPER_FILE = "paper_exp2.json"  # In this package; its "source" names the paper's tables.
METRIC = "position_mm"


def paper() -> dict:
  """The paper's Exp2S and Exp2R tables (``paper_exp2.json``): source, note and, per robot,
  ``experiments[robot]``: name, agents and ``scores[task][metric]``, one [mean, std] per agent."""
  return paper_tables.load(PAPER_FILE)


def paper_mean(robot: str, task: str, agent: str) -> float | None:
  """The paper's mean position error (mm) of ``agent`` on ``robot``'s ``task``, if it has one."""
  experiment = paper()["experiments"].get(paper_tables.paper_robot(robot))
  if experiment is None or agent not in experiment["agents"] or task not in experiment["scores"]:
    return None
  return experiment["scores"][task][METRIC][experiment["agents"].index(agent)][0]


@dataclasses.dataclass(frozen=True)
class Overview:
  robot: str
  profile: str
  eval_mode: str
  table: Table
  estimates: dict[tuple[str, str], ranking.Estimate]  # By (agent, task), for the table's cells.
  marks: dict[tuple[str, str], str] = dataclasses.field(default_factory=dict)
  """By (agent, task): ``ranking.COMPLETED_MARK`` after a completed target's figure, else ''."""

  @property
  def title(self) -> str:
    return f"{self.robot} overview · {self.profile} profile · {self.eval_mode}"

  @property
  def anchor(self) -> str:
    return f"overview-{self.robot}-{self.profile}-{self.eval_mode}"


def _cell(estimate: ranking.Estimate, reference: float | None, mark: str = "") -> str:
  text = ranking.mean_and_std(estimate) + mark
  return text if reference is None else f"{text} ({reference:.2f})"


def overviews(board: ranking.Leaderboard) -> tuple[Overview, ...]:
  """The overview of every robot, profile and eval mode with a plain-task record on ``board``."""
  cells: dict[tuple[str, str, str], dict[tuple[str, str], ranking.Estimate]] = {}
  marks: dict[tuple[str, str, str], dict[tuple[str, str], str]] = {}
  for group, entry in ranking.plain_entries(board):
    agent, profile, eval_mode = entry.setting
    cells.setdefault((group.robot, profile, eval_mode), {})[agent, group.task] = entry.estimates[
      METRIC
    ]
    marks.setdefault((group.robot, profile, eval_mode), {})[agent, group.task] = (
      entry.completion_mark
    )
  tables = []
  for (robot, profile, eval_mode), estimates in cells.items():  # Already in the groups' order.
    tasks = sorted({task for _, task in estimates}, key=suite.TASKS.index)
    names = sorted(
      {agent for agent, _ in estimates}, key=lambda agent: ranking.known_first(agent, agents.AGENTS)
    )
    experiment = paper()["experiments"].get(paper_tables.paper_robot(robot))
    caption = "position error (mm), mean ± std over seeds of the module-averaged error; " + (
      f"in brackets the paper's {experiment['name']} mean"
      if experiment
      else "the paper has no table for this robot"
    )
    if any(marks[robot, profile, eval_mode].values()):
      caption += f"; {ranking.COMPLETED_NOTE}"
    missing = [agent for agent in agents.AGENTS if agent not in names]
    if missing:
      caption += f"; no record yet of {', '.join(missing)}"
    rows = tuple(
      (
        agent,
        *(
          _cell(
            estimates[agent, task],
            paper_mean(robot, task, agent),
            marks[robot, profile, eval_mode][agent, task],
          )
          if (agent, task) in estimates
          else "-"
          for task in tasks
        ),
      )
      for agent in names
    )
    tables.append(
      Overview(
        robot,
        profile,
        eval_mode,
        Table(caption, ("agent", *tasks), rows, label_columns=1),
        estimates,
        marks[robot, profile, eval_mode],
      )
    )
  return tuple(
    sorted(
      tables,
      key=lambda view: ranking.setting_order(view.robot, view.profile, view.eval_mode),
    )
  )


def about_paper() -> str:
  """What the bracketed values are and how they differ from ours, for each page."""
  return f"Bracketed values: {paper()['source']} {paper()['note']}"
