"""Every shown row of the leaderboard as one CSV file (``leaderboard/leaderboard.csv``), for
spreadsheets and scripts: one line per physics version, robot, task, agent, profile and eval mode
(the newest record of each), with every metric's mean, standard deviation and bootstrap interval
over seeds; the current physics' rows first, then each earlier version's.

Figures are written in full (``repr``), not rounded as the pages show them; a metric the record
does not hold, or an interval with fewer than ``ranking.MIN_SEEDS_FOR_INTERVAL`` seeds, is empty.
``verified`` is ``true`` where the zoo's weights re-score the record (``verified``).
"""

import csv
import io
import pathlib

from softbench import records
from softbench.leaderboard import links
from softbench.leaderboard import ranking

FILE_NAME = "leaderboard.csv"
_SETTING = ("physics", "robot", "task", "variant", "agent", "profile", "eval_mode", "seeds")
_STATISTICS = ("mean", "std", "ci_low", "ci_high")
HEADER = (
  *_SETTING,
  *(f"{metric}_{statistic}" for metric in records.METRICS for statistic in _STATISTICS),
  "record",
  "video",
  "verified",
)


def _figures(estimate: ranking.Estimate | None) -> list[str]:
  if estimate is None:
    return [""] * len(_STATISTICS)
  low, high = estimate.interval if estimate.interval is not None else ("", "")
  return [repr(value) if value != "" else "" for value in (estimate.mean, estimate.std, low, high)]


def render(board: ranking.Leaderboard, out: pathlib.Path) -> str:
  """The CSV text of ``board``'s shown rows, groups in page order, each group ranked; links
  relative to the folder ``out``."""
  text = io.StringIO()
  writer = csv.writer(text, lineterminator="\n")
  writer.writerow(HEADER)
  for shown in (board, *board.earlier):
    _write_rows(writer, shown, out)
  return text.getvalue()


def _write_rows(writer, board: ranking.Leaderboard, out: pathlib.Path) -> None:
  for group in board.groups:
    for entry in group.entries:
      agent, profile, eval_mode = entry.setting
      row = [board.physics, group.robot, group.task, group.variant, agent, profile, eval_mode]
      row.append(str(entry.record["seeds"]))
      for metric in records.METRICS:
        row += _figures(entry.estimates.get(metric))
      row += [links.record(entry, out), links.video(entry, out) or ""]
      row.append("true" if board.is_verified(entry) else "false")
      writer.writerow(row)
