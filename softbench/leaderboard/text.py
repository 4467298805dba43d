"""The ranking as ``softbench leaderboard`` prints it: one aligned table per robot and task."""

import pathlib

from softbench.leaderboard import ranking
from softbench.leaderboard import records

_COLUMN_GAP = "  "


def _aligned(rows: list[list[str]], right: set[int]) -> list[str]:
  widths = [max(len(row[k]) for row in rows) for k in range(len(rows[0]))]
  return [_COLUMN_GAP.join(cell.rjust(width) if k in right else cell.ljust(width)
                           for k, (cell, width) in enumerate(zip(row, widths))).rstrip()
          for row in rows]


def summary(board: ranking.Leaderboard, results: pathlib.Path) -> str:
  """The first line: how many records, from where, and how to read the figures."""
  if not board.record_count:
    where = "no folder" if not pathlib.Path(results).exists() else "an empty folder"
    option = "" if pathlib.Path(results) == records.DEFAULT_FOLDER else f" --results {results}"
    return (f"no result records in {results} ({where}); make one with softbench run, e.g. "
            f"softbench run --task spiral --agent smpl{option}")
  return (f"{board.record_count} result record(s) in {results}, newest {board.latest_date}; "
          f"one row per agent, profile and eval mode (its newest record), ranked by position "
          f"error; mean ± std over seeds [{ranking.CONFIDENCE:.0%} bootstrap CI of the mean]")


def table(group: ranking.Group) -> str:
  """The title, the ranked rows and the superseded records of one group."""
  header = ["#", "agent", "profile", "eval", "seeds"]
  header += [ranking.METRIC_LABELS[name] for name in group.metrics]
  rows = [header]
  for place, entry in enumerate(group.entries, start=1):
    rows.append([str(place), *entry.setting, str(entry.record["seeds"])] +
                [ranking.cell(entry.estimates.get(name)) for name in group.metrics])
  lines = [group.title, *("  " + line for line in _aligned(rows, right={0, 4}))]
  for entry in group.superseded:
    lines.append(f"  superseded: {entry.path.name} ({entry.label}, {entry.record['date']}, "
                 f"position {ranking.cell(entry.estimates[ranking.RANKED_BY])} mm)")
  return "\n".join(lines)


def report(board: ranking.Leaderboard, results: pathlib.Path) -> str:
  """The whole printout."""
  return "\n\n".join([summary(board, results), *(table(group) for group in board.groups)])
