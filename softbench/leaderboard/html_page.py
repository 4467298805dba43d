"""The leaderboard as one self-contained static page (``leaderboard/index.html``), rendered from the
Jinja2 template ``templates/index.html.j2`` (inline CSS and JavaScript, no external resource).

The page's model is built here: per robot the overview of every agent on every task and the
aggregate across tasks (IQM, its stratified bootstrap interval, the performance profiles); per
robot and task one board per profile and eval mode, whose table sorts on a click and whose charts
draw each metric's mean on a log axis with its bootstrap interval; then the Exp1S records in the
paper's layout with the forgetting matrix as a heat map. Every board carries its profile and eval
mode, which the page's filters show or hide (without JavaScript, every board shows). The page
carries no time of its own, so the same records give the same bytes.
"""

from collections.abc import Iterable
import dataclasses
import pathlib

import jinja2
import numpy as np

from softbench import agents
from softbench import profiles
from softbench.leaderboard import aggregate
from softbench.leaderboard import continual_board
from softbench.leaderboard import csv_table
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import links
from softbench.leaderboard import log_chart
from softbench.leaderboard import overview
from softbench.leaderboard import ranking
from softbench.leaderboard import winners
from softbench.records import fields as record_fields

_HEAT_LOW = (247, 251, 255)  # (RGB) Heat-map colour of 0 %.
_HEAT_HIGH = (8, 48, 107)  # (RGB) Heat-map colour of the matrix's largest value.
_HEAT_LIGHT_TEXT_FROM = 0.5  # Fraction of the largest value from which a cell's text is white.
_TEMPLATE = "index.html.j2"  # In templates/, beside its style.css and page.js.

_ENVIRONMENT = jinja2.Environment(
  loader=jinja2.PackageLoader("softbench.leaderboard", "templates"),
  autoescape=True,
  undefined=jinja2.StrictUndefined,
  trim_blocks=True,
  lstrip_blocks=True,
  keep_trailing_newline=True,
)


@dataclasses.dataclass(frozen=True)
class Cell:
  """One table cell: its text, and what a numeric column sorts by (``None``: the text)."""

  text: str
  value: float | None = None
  interval: str | None = None  # A figure's bootstrap interval, shown after it, muted.
  paper: str | None = None  # The paper's value for the same setting, shown after it, in brackets.
  href: str | None = None
  title: str | None = None
  figure: bool = False  # A mean ± std (left-aligned, tabular digits), else a plain number.
  best: bool = False  # The best learned agent's figure of its column (``winners``).


@dataclasses.dataclass(frozen=True)
class SortableTable:
  columns: tuple[tuple[str, bool], ...]  # (name, numeric) per column.
  rows: tuple[tuple[Cell, ...], ...]
  caption: str = ""
  row_classes: tuple[str, ...] = ()  # Per row: "oracle" (shown apart, after the others) or "".


@dataclasses.dataclass(frozen=True)
class Board:
  """One robot, profile and eval mode's part of a section: a title, a table, charts."""

  anchor: str
  title: str
  profile: str
  eval_mode: str
  table: SortableTable
  charts: tuple[log_chart.Chart, ...] = ()
  image: str | None = None  # A figure file beside the page.


def _figure(
  estimate: ranking.Estimate | None, paper: float | None = None, mark: str = "", best: bool = False
) -> Cell:
  """A mean ± std cell (followed by ``mark``), with its interval and the paper's value; ``best``
  marks the best learned agent's."""
  if estimate is None:
    return Cell("-")
  return Cell(
    ranking.mean_and_std(estimate) + mark,
    estimate.mean,
    None if estimate.interval is None else ranking.interval_text(estimate),
    None if paper is None else f"{paper:.2f}",
    title=BEST_TITLE if best else None,
    figure=True,
    best=best,
  )


BEST_TITLE = "the best learned agent on this task"
VERIFIED_TITLE = "the zoo's weights re-score this record (softbench zoo verify)"
UNVERIFIED_TITLE = "not re-scored from the zoo: its figures rest on the submitter alone"
ORACLE_NOTE = "oracle: uses the simulator itself (a bound on what the physics allows), not ranked"


def _metric_caption(metric: str) -> str:
  return (
    f"{ranking.METRIC_LABELS[metric]}, mean over seeds (log axis, lower is better); whiskers: "
    f"{ranking.CONFIDENCE:.0%} bootstrap CI"
  )


def _task_boards(
  group: ranking.Group, out: pathlib.Path, board: ranking.Leaderboard, prefix: str = ""
) -> tuple[Board, ...]:
  """``group``'s rows split by profile and eval mode, each ranked, with a chart per metric and
  each record's verification (``board.is_verified``); ``prefix`` begins each board's anchor (an
  earlier physics version's section)."""
  by_setting: dict[tuple[str, str], list[ranking.BoardEntry]] = {}
  for entry in group.entries:  # Already ranked.
    by_setting.setdefault(entry.setting[1:], []).append(entry)
  videos = any(links.video(entry, out) for entry in group.entries)
  columns = (
    ("#", True),
    ("agent", False),
    ("seeds", True),
    *((ranking.METRIC_LABELS[metric], True) for metric in group.metrics),
    *((("video", False),) if videos else ()),
    ("verified", False),
    ("record", False),
  )
  boards = []
  for (profile, eval_mode), entries in sorted(
    by_setting.items(), key=lambda item: ranking.setting_order(group.robot, *item[0])
  ):
    rows = []
    places = ranking.places(tuple(entries))
    for place, entry in zip(places, entries):
      video = links.video(entry, out)
      rows.append(
        (
          Cell(place, int(place) if place.isdigit() else len(entries) + 1),
          Cell(entry.shown_setting[0]),
          Cell(str(entry.record["seeds"]), entry.record["seeds"]),
          *(_figure(entry.estimates.get(metric)) for metric in group.metrics),
          *(((Cell("video", href=video) if video else Cell("-")),) if videos else ()),
          Cell("✓", title=VERIFIED_TITLE)
          if board.is_verified(entry)
          else Cell("no", title=UNVERIFIED_TITLE),
          Cell("json", href=links.record(entry, out), title=entry.path.name),
        )
      )
    oracle = tuple("oracle" if place == ranking.ORACLE_PLACE else "" for place in places)
    charts = tuple(
      log_chart.chart(
        [
          (entry.setting[0], entry.label, entry.estimates[metric])
          for entry in entries
          if metric in entry.estimates
        ],
        _metric_caption(metric),
      )
      for metric in group.metrics
    )
    boards.append(
      Board(
        f"{prefix}{group.anchor}-{profile}-{eval_mode}",
        f"{profile} profile · {eval_mode}",
        profile,
        eval_mode,
        SortableTable(columns, tuple(rows), ORACLE_NOTE if any(oracle) else "", oracle),
        charts,
      )
    )
  return tuple(boards)


def _overview_board(view: overview.Overview) -> Board:
  """The overview's table: the best learned agent of each column marked, the oracles last."""
  shown = [row[0] for row in view.table.rows]
  agents_shown = [a for a in shown if not agents.is_oracle(a)] + [
    a for a in shown if agents.is_oracle(a)
  ]
  tasks = view.table.header[1:]
  best = winners.best_cells(view)
  rows = tuple(
    (
      Cell(f"{agent} (oracle)" if agents.is_oracle(agent) else agent),
      *(
        _figure(
          view.estimates.get((agent, task)),
          overview.paper_mean(view.robot, task, agent),
          view.marks.get((agent, task), ""),
          (agent, task) in best,
        )
        for task in tasks
      ),
    )
    for agent in agents_shown
  )
  columns = (("agent", False), *((f"{task} (mm)", True) for task in tasks))
  caption = view.table.caption + f"; [{ranking.CONFIDENCE:.0%} bootstrap CI]; ★ {BEST_TITLE}"
  oracle = tuple("oracle" if agents.is_oracle(agent) else "" for agent in agents_shown)
  return Board(
    view.anchor,
    view.title,
    view.profile,
    view.eval_mode,
    SortableTable(columns, rows, caption, oracle),
  )


def _winner_boards(views: tuple[overview.Overview, ...], linked: bool = True) -> list[dict]:
  """The first screen: per profile and eval mode, each robot's best learned agent per task and
  the oracle's figure apart (``winners``); ``linked``: each robot links to its overview (which
  only the current physics' section has)."""
  found = winners.rows(views)
  boards: dict[tuple[str, str], dict] = {}
  for row in found:
    view = row.view
    board = boards.setdefault(
      (view.profile, view.eval_mode),
      {
        "profile": view.profile,
        "eval_mode": view.eval_mode,
        "title": f"{view.profile} profile · eval {view.eval_mode}",
        "tasks": winners.tasks(views),
        "rows": [],
      },
    )
    board["rows"].append(
      {
        "robot": view.robot,
        "anchor": view.anchor if linked else None,
        "cells": [
          {
            "task": best.task,
            "agent": best.agent,
            "figure": best.figure,
            "oracle": "; ".join(
              f"{agent} {ranking.mean_and_std(estimate)}" for agent, estimate in best.oracles
            ),
          }
          for best in row.best
        ],
      }
    )
  return list(boards.values())


def _aggregate_board(view: aggregate.View) -> Board:
  rows = []
  for found in view.aggregates:
    runs = sum(len(task) for task in found.runs)
    if found.missing:  # No IQM that compares.
      rows.append((Cell(found.agent), Cell(str(runs), runs), Cell(found.missing_text), Cell("-")))
      continue
    median = float(np.median(np.concatenate(found.runs)))
    low, high = found.interval
    rows.append(
      (
        Cell(found.agent),
        Cell(str(runs), runs),
        Cell(
          ranking.number(found.iqm),
          found.iqm,
          f"[{ranking.number(low)}, {ranking.number(high)}]",
          figure=True,
        ),
        Cell(ranking.number(median), median),
      )
    )
  columns = (("agent", False), ("runs", True), ("IQM", True), ("median", True))
  estimates = [
    (found.agent, found.agent, ranking.Estimate(found.iqm, None, found.interval))
    for found in view.complete
  ]
  chart = log_chart.chart(
    estimates,
    f"IQM of the normalised tip error (%), log axis; whiskers: {ranking.CONFIDENCE:.0%} "
    "stratified bootstrap CI",
  )
  return Board(
    view.anchor,
    view.title,
    view.profile,
    view.eval_mode,
    SortableTable(columns, tuple(rows), view.table.caption),
    (chart,),
    view.image,
  )


def _rgb(colour: Iterable[float]) -> str:
  return "#" + "".join(f"{round(channel):02x}" for channel in colour)


def _heat_map(table, values: list[list[float | None]]) -> dict:
  """A matrix ``table`` (a label column, then a figure per column) with each cell's colour from
  ``values`` (light 0, dark the largest value; None: a configuration not yet learned)."""
  highest = max(value for row in values for value in row if value is not None)
  rows = []
  for row, texts in zip(values, table.rows):
    cells = []
    for value, text in zip(row, texts[1:]):
      if value is None:  # Not yet learned at this stage.
        cells.append(None)
        continue
      share = value / highest if highest > 0 else 0.0
      colour = _rgb(low + share * (high - low) for low, high in zip(_HEAT_LOW, _HEAT_HIGH))
      ink = "#ffffff" if share >= _HEAT_LIGHT_TEXT_FROM else "#1b1f24"
      cells.append({"text": text, "value": repr(value), "colour": colour, "ink": ink})
    rows.append({"label": texts[0], "cells": cells})
  return {
    "table": table,
    "rows": rows,
    "low": _rgb(_HEAT_LOW),
    "high": _rgb(_HEAT_HIGH),
    "highest": ranking.number(highest),
  }


def _by_robot(boards: Iterable[tuple[str, Board]]) -> dict[str, list[Board]]:
  grouped: dict[str, list[Board]] = {}
  for robot, board in boards:
    grouped.setdefault(robot, []).append(board)
  return grouped


def _filters(board: ranking.Leaderboard) -> dict[str, list[str]]:
  """The profiles and eval modes the records hold, in their registry order: the current
  physics' first (the first is chosen when the page opens), then the earlier versions' others."""
  boards = (board, *board.earlier)
  chosen: dict[str, list[str]] = {"profiles": [], "eval_modes": []}
  for shown in boards:
    entries = [entry for group in shown.groups for entry in group.entries]
    found_profiles = {entry.setting[1] for entry in entries}
    found_profiles |= {entry.setting[1] for group in shown.exp1s for entry in group.entries}
    found_profiles |= {group.profile for group in shown.continual}
    found_modes = {entry.setting[2] for entry in entries}
    for key, found, order in (
      ("profiles", found_profiles, profiles.PROFILES),
      ("eval_modes", found_modes, record_fields.ERROR_SOURCES),
    ):
      new = sorted(set(found) - set(chosen[key]), key=lambda name: ranking.known_first(name, order))
      chosen[key] += new
  return chosen


@dataclasses.dataclass(frozen=True)
class Earlier:
  """An earlier physics version's records, ranked among themselves, as the page shows them."""

  physics: str
  description: str
  record_count: int
  latest_date: str | None
  task_groups: list
  exp1s: tuple
  continual: tuple


def _earlier(board: ranking.Leaderboard, out: pathlib.Path) -> Earlier:
  prefix = f"physics-{board.physics}-"
  return Earlier(
    board.physics,
    board.physics_description,
    board.record_count,
    board.latest_date,
    [(group, _task_boards(group, out, board, prefix)) for group in board.groups],
    board.exp1s,
    board.continual,
  )


def render(board: ranking.Leaderboard, results: pathlib.Path, out: pathlib.Path) -> str:
  """The page, with links relative to the folder ``out`` it is written to."""
  views = overview.overviews(board)
  return _ENVIRONMENT.get_template(_TEMPLATE).render(
    board=board,
    results_link=links.relative(pathlib.Path(results), out),
    csv_file=csv_table.FILE_NAME,
    filters=_filters(board),
    overviews=_by_robot((view.robot, _overview_board(view)) for view in views),
    winners=_winner_boards(views),
    earlier_winners=[
      (older.physics_description, _winner_boards(overview.overviews(older), linked=False))
      for older in board.earlier
    ],
    about_paper=overview.about_paper(),
    across=_by_robot((view.robot, _aggregate_board(view)) for view in aggregate.views(board)),
    task_groups=[(group, _task_boards(group, out, board)) for group in board.groups],
    exp1s=board.exp1s,
    physics=board.physics_description,
    earlier=[_earlier(older, out) for older in board.earlier],
    exp1s_explanation=exp1s_board.explanation(),
    exp1s_about_paper=exp1s_board.about_paper(),
    exp1s_tables=exp1s_board.score_tables,
    exp1s_describe=exp1s_board.describe,
    exp1s_heat=lambda entry: _heat_map(exp1s_board.forgetting_table(entry), entry.forgetting()),
    continual=board.continual,
    continual_explanation=continual_board.explanation(),
    continual_tables=lambda group: (
      continual_board.table(group),
      continual_board.diagonal_table(group),
    ),
    continual_heat=lambda entry: _heat_map(
      continual_board.matrix_table(entry), continual_board.matrix_values(entry)
    ),
    record_link=lambda entry: links.record(entry, out),
    confidence=f"{ranking.CONFIDENCE:.0%}",
    resamples=f"{ranking.BOOTSTRAP_RESAMPLES:,}",
    min_seeds=ranking.MIN_SEEDS_FOR_INTERVAL,
  )
