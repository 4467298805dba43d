"""The results tables of the documentation, generated from the records: ``TABLES`` maps each
name to a function of the leaderboard (``ranking.Leaderboard``, built from the records) that
returns a ``figure_table.Table``. Every figure is the leaderboard's: mean ± standard deviation over
seeds (population, ddof 0) of the newest record of each setting. No table shows a figure that
changes from machine to machine (wall times are the page's). The pages' blocks that hold them are
``doc_pages``'.
"""

import dataclasses
from typing import Callable

from softbench import agents
from softbench import metrics
from softbench import suite
from softbench.leaderboard import continual_board
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import overview
from softbench.leaderboard import paper_tables
from softbench.leaderboard import ranking
from softbench.leaderboard.figure_table import Table

METRIC = "position_mm"
TIP_METRIC = "normalised_tip_percent"


class DocTableError(ValueError):
  """A table cannot be built, or a page's table block is unknown or malformed (one line naming
  the page and line)."""


@dataclasses.dataclass(frozen=True)
class TableSetting:
  """What a column of records stands for: robot, profile and eval mode."""

  robot: str
  profile: str = "default"
  eval_mode: str = "physics"

  def __str__(self) -> str:
    return f"{self.robot}, {self.profile} profile, eval {self.eval_mode}"


def _entries(board: ranking.Leaderboard) -> dict[tuple[TableSetting, str, str], ranking.BoardEntry]:
  """The shown entry of each (setting, task, agent), plain tasks only."""
  return {
    (TableSetting(group.robot, *entry.setting[1:]), group.task, entry.setting[0]): entry
    for group, entry in ranking.plain_entries(board)
  }


def _agents_in(names) -> list[str]:
  """``names`` in registry order, then any others by name."""
  return sorted(set(names), key=lambda agent: ranking.known_first(agent, agents.AGENTS))


def _with_paper(estimate, robot: str, task: str, agent: str) -> str:
  """``mean ± std``, then the paper's mean in brackets where it has one."""
  paper = overview.paper_mean(robot, task, agent)
  text = ranking.mean_and_std(estimate)
  return text if paper is None else f"{text} ({paper:.2f})"


def _over_seeds(entry: ranking.BoardEntry, metric: str, module: int) -> metrics.Statistic:
  """Mean and std over seeds of one module's (0-based) episode error (``ranking.mean_and_std``
  formats it like an ``Estimate``: it reads only ``mean`` and ``std``)."""
  return metrics.Statistic.of(
    [seed[metric]["per_module"][module] for seed in entry.record["per_seed"]]
  )


def overview_table(setting: TableSetting) -> Callable[[ranking.Leaderboard], Table]:
  """The leaderboard's overview of ``setting``: agents by tasks, the paper's mean in brackets."""

  def table(board: ranking.Leaderboard) -> Table:
    for view in overview.overviews(board):
      if (view.robot, view.profile, view.eval_mode) == (
        setting.robot,
        setting.profile,
        setting.eval_mode,
      ):
        return dataclasses.replace(view.table, caption=f"{setting}: {view.table.caption}")
    raise DocTableError(f"no records of {setting}")

  return table


def modules_table(setting: TableSetting, task: str) -> Callable[[ranking.Leaderboard], Table]:
  """Per-module position error of every agent on one task, ranked as the leaderboard ranks."""

  def table(board: ranking.Leaderboard) -> Table:
    ranked = [
      entry
      for group in board.groups  # Ranked already, best first.
      if (group.robot, group.task, group.variant) == (setting.robot, task, "")
      for entry in group.entries
      if entry.setting[1:] == (setting.profile, setting.eval_mode)
    ]
    if not ranked:
      raise DocTableError(f"no records of {task} on {setting}")
    modules = len(ranked[0].record["per_seed"][0][METRIC]["per_module"])
    rows = tuple(
      (
        entry.record["agent"],
        *(ranking.mean_and_std(_over_seeds(entry, METRIC, module)) for module in range(modules)),
        ranking.mean_and_std(entry.estimates[METRIC]),
        ranking.mean_and_std(entry.estimates[TIP_METRIC]),
      )
      for entry in ranked
    )
    return Table(
      f"{task} on {setting}: position error (mm) per module and averaged over "
      f"modules, normalised tip error (%), mean ± std over seeds",
      (
        "agent",
        *(f"module {k + 1}" for k in range(modules)),
        "mean",
        "tip error (%)",
      ),
      rows,
      label_columns=1,
    )

  return table


def comparison_table(
  first: TableSetting, second: TableSetting
) -> Callable[[ranking.Leaderboard], Table]:
  """Every agent's position error on ``first`` -> on ``second``, per task (``-``: no record)."""

  def table(board: ranking.Leaderboard) -> Table:
    found = _entries(board)
    shown = [(task, agent) for where, task, agent in found if where in (first, second)]
    columns = sorted({task for task, _ in shown}, key=suite.TASKS.index)

    def cell(where: TableSetting, task: str, agent: str) -> str:
      entry = found.get((where, task, agent))
      if entry is None:
        return "-"
      return ranking.mean_and_std(entry.estimates[METRIC]) + entry.completion_mark

    marked = any(
      entry.completion_mark for (where, _, _), entry in found.items() if where in (first, second)
    )
    rows = tuple(
      (agent, *(f"{cell(first, task, agent)} -> {cell(second, task, agent)}" for task in columns))
      for agent in _agents_in(agent for _, agent in shown)
    )
    return Table(
      f"position error (mm), mean ± std over seeds of the module-averaged error: "
      f"{first} -> {second}" + (f"; {ranking.COMPLETED_NOTE}" if marked else ""),
      ("agent", *columns),
      rows,
      label_columns=1,
    )

  return table


def eval_modes_table(
  robot: str, task: str, profile: str, modes: tuple[str, ...]
) -> Callable[[ranking.Leaderboard], Table]:
  """Every agent's position error on one task under each eval mode (the error fed back)."""

  def table(board: ranking.Leaderboard) -> Table:
    found = _entries(board)
    settings = [TableSetting(robot, profile, mode) for mode in modes]
    names = _agents_in(
      agent
      for where, on, agent in found
      if on == task and where in settings and where.eval_mode != "physics"
    )
    rows = tuple(
      (
        agent,
        *(
          "-"
          if (where, task, agent) not in found
          else ranking.mean_and_std(found[where, task, agent].estimates[METRIC])
          for where in settings
        ),
      )
      for agent in names
    )
    return Table(
      f"{task} on {robot}, {profile} profile: position error (mm), mean ± std over "
      f"seeds of the module-averaged error, by the error fed back (eval mode)",
      ("agent", *modes),
      rows,
      label_columns=1,
    )

  return table


def spiral_headline(settings: tuple[TableSetting, ...]) -> Callable[[ranking.Leaderboard], Table]:
  """Every agent on the spiral of several settings, the paper's mean in brackets."""

  def table(board: ranking.Leaderboard) -> Table:
    found = _entries(board)
    names = _agents_in(
      agent for where, task, agent in found if task == "spiral" and where in settings
    )
    rows = tuple(
      (
        agent,
        *(
          "-"
          if (where, "spiral", agent) not in found
          else _with_paper(
            found[where, "spiral", agent].estimates[METRIC], where.robot, "spiral", agent
          )
          for where in settings
        ),
      )
      for agent in names
    )
    return Table(
      "spiral, closed loop in physics: position error (mm), mean ± std over seeds of "
      "the module-averaged error; in brackets the paper's mean (Exp2S for the tendon "
      "arms, Exp2R, the real robot, for pneumatic-433)",
      ("agent", *(f"{where.robot} {where.profile}" for where in settings)),
      rows,
      label_columns=1,
    )

  return table


def _exp1s_entry(board: ranking.Leaderboard, family: str, profile: str) -> exp1s_board.Exp1sEntry:
  """The shown SMPL Exp1S entry of ``family`` (e.g. ``tendon-local``) at ``profile``."""
  for group in board.exp1s:
    if not group.variant and group.robots[0].rsplit("-", 1)[0] == family:
      for entry in group.entries:
        if entry.setting == ("smpl", profile):
          return entry
  raise DocTableError(f"no Exp1S record of smpl on the {family} family at the {profile} profile")


def _exp1s_paper_mean(robot: str, loop: str, task: str) -> float | None:
  paper, robot = exp1s_board.paper(), paper_tables.paper_robot(robot)
  if robot not in paper["robots"] or task not in paper["scores"][loop]:
    return None
  return paper["scores"][loop][task][METRIC][paper["robots"].index(robot)][0]


def _exp1s_figure(
  entry: exp1s_board.Exp1sEntry, loop: str, task: str, index: int, metric: str = METRIC
) -> str:
  """One configuration's (0-based) error, mean ± std over seeds, as the Exp1S section prints it."""
  statistic = entry.statistic(loop, task, index, metric)
  return exp1s_board.figure(statistic.mean, statistic.std)


def _exp1s_cell(entry: exp1s_board.Exp1sEntry, loop: str, task: str, index: int) -> str:
  paper = _exp1s_paper_mean(entry.record["robots"][index], loop, task)
  text = _exp1s_figure(entry, loop, task, index)
  return text if paper is None else f"{text} ({paper:.2f})"


def exp1s_table(family: str, profile: str) -> Callable[[ranking.Leaderboard], Table]:
  """Exp1S of one family and profile: the end effector's position error per configuration and
  task (closed loop, and open loop on the spiral), the paper's mean in brackets."""

  def table(board: ranking.Leaderboard) -> Table:
    entry = _exp1s_entry(board, family, profile)
    tasks = entry.record["tasks"]
    rows = tuple(
      (
        robot,
        *(_exp1s_cell(entry, "closed", task, index) for task in tasks),
        _exp1s_figure(entry, "closed", "spiral", index, TIP_METRIC),
        _exp1s_cell(entry, "open", "spiral", index),
      )
      for index, robot in enumerate(entry.record["robots"])
    )
    return Table(
      f"Exp1S, {family} family, {profile} profile, {entry.record['seeds']} seeds: "
      f"end-effector position error (mm), closed loop in physics unless said, mean ± "
      f"std over seeds; in brackets the paper's mean",
      ("configuration", *tasks, "tip error (%), spiral", "spiral, open loop"),
      rows,
      label_columns=1,
    )

  return table


def exp1s_comparison_table(
  first: str, second: str, profile: str
) -> Callable[[ranking.Leaderboard], Table]:
  """Exp1S closed-loop position error of two families' arms of as many modules side by side."""

  def table(board: ranking.Leaderboard) -> Table:
    entries = [_exp1s_entry(board, family, profile) for family in (first, second)]
    tasks = [task for task in entries[0].record["tasks"] if task in entries[1].record["tasks"]]
    sizes = min(len(entry.record["robots"]) for entry in entries)
    rows = tuple(
      (
        f"{index + 1} module{'s' if index else ''}",
        *(
          " -> ".join(_exp1s_figure(entry, "closed", task, index) for entry in entries)
          for task in tasks
        ),
        " -> ".join(
          _exp1s_figure(entry, "closed", "spiral", index, TIP_METRIC) for entry in entries
        ),
      )
      for index in range(sizes)
    )
    return Table(
      f"Exp1S, {profile} profile, closed loop in physics: end-effector position error "
      f"(mm), mean ± std over seeds, {first}-N -> {second}-N",
      ("configuration", *tasks, "tip error (%), spiral"),
      rows,
      label_columns=1,
    )

  return table


def exp1s_headline(settings: tuple[tuple[str, str], ...]) -> Callable[[ranking.Leaderboard], Table]:
  """Exp1S spiral error per number of modules for several (family, profile), beside the paper."""

  def table(board: ranking.Leaderboard) -> Table:
    entries = [_exp1s_entry(board, *setting) for setting in settings]
    sizes = min(len(entry.record["robots"]) for entry in entries)
    papers = [
      _exp1s_paper_mean(entries[0].record["robots"][index], "closed", "spiral")
      for index in range(sizes)
    ]
    rows = tuple(
      (
        str(index + 1),
        *(_exp1s_figure(entry, "closed", "spiral", index) for entry in entries),
        "-" if papers[index] is None else f"{papers[index]:.2f}",
      )
      for index in range(sizes)
    )
    return Table(
      "Exp1S spiral, closed loop in physics: end-effector position error (mm), mean ± "
      "std over seeds, per number of modules; the paper's mean last",
      ("modules", *(f"{family} {profile}" for family, profile in settings), "paper"),
      rows,
      label_columns=1,
    )

  return table


TENDON_3 = TableSetting("tendon-3")
LOCAL_3 = TableSetting("tendon-local-3")
PNEUMATIC = TableSetting("pneumatic-433")
TENDON_3_PAPER = TableSetting("tendon-3", "paper")
LOCAL_3_PAPER = TableSetting("tendon-local-3", "paper")
PNEUMATIC_PAPER = TableSetting("pneumatic-433", "paper")


def continual_table(
  stream: str, family: str, profile: str, diagonal: bool = False
) -> Callable[[ranking.Leaderboard], Table]:
  """Every strategy's record of ``stream`` on ``family`` at ``profile`` (``continual_board``):
  their figures, training times left out, or with ``diagonal`` each configuration's error after
  its own stage and the forward transfer on it."""

  def table(board: ranking.Leaderboard) -> Table:
    for group in board.continual:
      if (group.stream, group.family, group.profile) == (stream, family, profile):
        if diagonal:
          return continual_board.diagonal_table(group)
        return continual_board.table(group, with_times=False)
    raise DocTableError(f"no continual record of stream {stream} on {family} at {profile}")

  return table


TABLES: dict[str, Callable[[ranking.Leaderboard], Table]] = {
  "headline-spiral": spiral_headline(
    (TENDON_3, TENDON_3_PAPER, LOCAL_3, LOCAL_3_PAPER, PNEUMATIC, PNEUMATIC_PAPER)
  ),
  "headline-exp1s-spiral": exp1s_headline(
    (
      ("tendon", "default"),
      ("tendon", "paper"),
      ("tendon-local", "default"),
      ("tendon-local", "paper"),
    )
  ),
  "overview-tendon-3-default": overview_table(TENDON_3),
  "overview-tendon-3-paper": overview_table(TENDON_3_PAPER),
  "overview-tendon-local-3-default": overview_table(LOCAL_3),
  "overview-tendon-local-3-paper": overview_table(LOCAL_3_PAPER),
  "overview-pneumatic-433-default": overview_table(PNEUMATIC),
  "overview-pneumatic-433-paper": overview_table(PNEUMATIC_PAPER),
  "modules-tendon-3-spiral-default": modules_table(TENDON_3, "spiral"),
  "modules-tendon-3-spiral-paper": modules_table(TENDON_3_PAPER, "spiral"),
  "modules-tendon-local-3-spiral-default": modules_table(LOCAL_3, "spiral"),
  "modules-tendon-local-3-spiral-paper": modules_table(LOCAL_3_PAPER, "spiral"),
  "modules-pneumatic-433-spiral-default": modules_table(PNEUMATIC, "spiral"),
  "modules-pneumatic-433-spiral-paper": modules_table(PNEUMATIC_PAPER, "spiral"),
  "profiles-tendon-3": comparison_table(TENDON_3, TENDON_3_PAPER),
  "profiles-pneumatic-433": comparison_table(PNEUMATIC, PNEUMATIC_PAPER),
  "profiles-tendon-local-3": comparison_table(LOCAL_3, LOCAL_3_PAPER),
  "plants-tendon-3-tendon-local-3": comparison_table(TENDON_3, LOCAL_3),
  "plants-tendon-3-tendon-local-3-paper": comparison_table(TENDON_3_PAPER, LOCAL_3_PAPER),
  "eval-modes-tendon-3-spiral": eval_modes_table(
    "tendon-3", "spiral", "default", ("physics", "model", "open-loop")
  ),
  "eval-modes-tendon-local-3-spiral-paper": eval_modes_table(
    "tendon-local-3", "spiral", "paper", ("physics", "model")
  ),
  "exp1s-tendon-default": exp1s_table("tendon", "default"),
  "exp1s-tendon-paper": exp1s_table("tendon", "paper"),
  "exp1s-tendon-local-default": exp1s_table("tendon-local", "default"),
  "exp1s-families-default": exp1s_comparison_table("tendon", "tendon-local", "default"),
  "exp1s-tendon-local-paper": exp1s_table("tendon-local", "paper"),
  "exp1s-families-paper": exp1s_comparison_table("tendon", "tendon-local", "paper"),
  # A stream's table joins once its records are in (every named table appears in the docs).
  "continual-grow-tendon-default": continual_table("grow", "tendon", "default"),
  "continual-grow-tendon-default-diagonal": continual_table("grow", "tendon", "default", True),
  "continual-payload-tendon-default": continual_table("payload", "tendon", "default"),
  "continual-payload-tendon-default-diagonal": continual_table(
    "payload", "tendon", "default", True
  ),
  "continual-degrade-tendon-default": continual_table("degrade", "tendon", "default"),
  "continual-degrade-tendon-default-diagonal": continual_table(
    "degrade", "tendon", "default", True
  ),
  "continual-grow-tendon-local-default": continual_table("grow", "tendon-local", "default"),
  "continual-grow-tendon-local-default-diagonal": continual_table(
    "grow", "tendon-local", "default", True
  ),
}
