"""The ranking as ``softbench leaderboard`` prints it: the overviews, then one aligned table per
robot and task, then the Exp1S sections."""

import pathlib

from softbench import records
from softbench.leaderboard import continual_board
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import figure_table
from softbench.leaderboard import overview
from softbench.leaderboard import ranking

_COLUMN_GAP = "  "


def _aligned(rows: list[list[str]], right: set[int]) -> list[str]:
  widths = [max(len(row[k]) for row in rows) for k in range(len(rows[0]))]
  return [
    _COLUMN_GAP.join(
      cell.rjust(width) if k in right else cell.ljust(width)
      for k, (cell, width) in enumerate(zip(row, widths))
    ).rstrip()
    for row in rows
  ]


def summary(board: ranking.Leaderboard, results: pathlib.Path, asked_for: str = "") -> str:
  """The first line: how many records (of those ``asked_for``, if only some), from where, and
  how to read the figures."""
  total = board.record_count + sum(older.record_count for older in board.earlier)
  if not total and asked_for:
    return f"no result records of {asked_for} in {results}"
  if not total:
    where = "no folder" if not pathlib.Path(results).exists() else "an empty folder"
    option = "" if pathlib.Path(results) == records.DEFAULT_FOLDER else f" --results {results}"
    return (
      f"no result records in {results} ({where}); make one with softbench run, e.g. "
      f"softbench run --task spiral --agent smpl{option}"
    )
  of = f" of {asked_for}" if asked_for else ""
  parts = [
    f"{board.record_count} result record(s){of} in {results}"
    + (f", newest {board.latest_date}" if board.record_count else "")
    + f", {board.physics_description}"
  ]
  parts += [
    f"{older.record_count} of {older.physics_description}, ranked apart below"
    for older in board.earlier
  ]
  if board.groups:
    parts.append(
      f"one row per agent, profile and eval mode (its newest record), ranked by "
      f"position error; mean ± std over seeds [{ranking.CONFIDENCE:.0%} bootstrap CI "
      f"of the mean]"
    )
  if board.exp1s:
    parts.append(
      "Exp1S: the newest record per agent and profile, in the paper's layout, mean ± std over seeds"
    )
  if board.continual:
    parts.append("continual: a table per stream, the newest record per strategy")
  return "; ".join(parts)


def table(group: ranking.Group) -> str:
  """The title, the ranked rows and the superseded records of one group."""
  header = ["#", "agent", "profile", "eval", "seeds"]
  header += [ranking.METRIC_LABELS[name] for name in group.metrics]
  rows = [header]
  for place, entry in zip(ranking.places(group.entries), group.entries):
    rows.append(
      [place, *entry.shown_setting, str(entry.record["seeds"])]
      + [ranking.cell(entry.estimates.get(name)) for name in group.metrics]
    )
  lines = [group.title, *("  " + line for line in _aligned(rows, right={0, 4}))]
  for entry in group.superseded:
    lines.append(
      f"  superseded: {entry.path.name} ({entry.label}, {entry.record['date']}, "
      f"position {ranking.cell(entry.estimates[ranking.RANKED_BY])} mm)"
    )
  return "\n".join(lines)


def figure_rows(table: figure_table.Table) -> list[str]:
  """A table of figures: its caption, then the aligned header and rows."""
  rows = [list(table.header), *map(list, table.rows)]
  right = set(range(table.label_columns, len(table.header)))
  return [f"  {table.caption}", *("    " + line for line in _aligned(rows, right))]


def exp1s_section(group: exp1s_board.Group) -> str:
  """The title, every shown entry's tables, the superseded records and the paper's source."""
  lines = [group.title]
  for entry in group.entries:
    lines.append(f"  {exp1s_board.describe(entry)}, {entry.path.name}")
    for exp1s in exp1s_board.tables(entry):
      lines += figure_rows(exp1s)
  for entry in group.superseded:
    lines.append(f"  superseded: {entry.path.name} ({entry.label}, {entry.record['date']})")
  lines.append(f"  {exp1s_board.about_paper()}")
  return "\n".join(lines)


def continual_section(group: continual_board.Group) -> str:
  """The title, the strategies' table, each strategy's error matrix and the superseded records."""
  lines = [
    group.title,
    *figure_rows(continual_board.table(group)),
    *figure_rows(continual_board.diagonal_table(group)),
  ]
  for entry in group.entries:
    lines.append(f"  {entry.label}: {entry.path.name}")
    lines += figure_rows(continual_board.matrix_table(entry))
  for entry in group.superseded:
    lines.append(f"  superseded: {entry.path.name} ({entry.label}, {entry.record['date']})")
  return "\n".join(lines)


def overview_section(views: tuple[overview.Overview, ...]) -> list[str]:
  """Every overview (its title and table), then what the bracketed values are."""
  if not views:
    return []
  return [
    *("\n".join([view.title, *figure_rows(view.table)]) for view in views),
    overview.about_paper(),
  ]


def report(board: ranking.Leaderboard, results: pathlib.Path, asked_for: str = "") -> str:
  """The whole printout (of the records ``asked_for``, if only some); each earlier physics
  version's records after the current one's, ranked among themselves."""
  sections = [
    summary(board, results, asked_for),
    *overview_section(overview.overviews(board)),
    *(table(group) for group in board.groups),
    *(exp1s_section(group) for group in board.exp1s),
    *(continual_section(group) for group in board.continual),
  ]
  for older in board.earlier:
    sections += [
      f"== earlier physics: {older.physics_description}, ranked apart ==",
      *(f"{table(group)}" for group in older.groups),
      *(exp1s_section(group) for group in older.exp1s),
      *(continual_section(group) for group in older.continual),
    ]
  return "\n\n".join(sections)
