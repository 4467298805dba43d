"""The leaderboard: result records ranked per robot and task, printed and written as pages.

``ranking`` (newest record per agent, profile and eval mode; mean, std and bootstrap interval
over seeds), ``overview`` (every agent on every task of a robot, beside the paper's Exp2S/Exp2R
values), ``aggregate`` (each agent across tasks: IQM, stratified bootstrap interval, performance
profiles), ``exp1s_board`` (Exp1S records in the paper's layout, beside the paper's values),
``figure_table`` (the tables every page renders alike), ``text`` (the printout),
``filters`` (the records of some robots, tasks, agents or profiles, for a partial printout),
``markdown_page`` and ``html_page`` (``README.md`` and ``index.html``, the latter from the Jinja2
template in ``templates/``, with ``log_chart``'s log-axis bar charts), ``csv_table``
(``leaderboard.csv``: every shown row), ``verified`` (the records the zoo's weights re-score),
``doc_tables`` (the results tables of the repository's
``README.md`` and ``docs/*.md``). The record formats themselves are ``softbench.records``'.
"""

import pathlib

from softbench import records
from softbench import storage
from softbench.leaderboard import aggregate
from softbench.leaderboard import csv_table
from softbench.leaderboard import filters
from softbench.leaderboard import html_page
from softbench.leaderboard import markdown_page
from softbench.leaderboard import ranking
from softbench.leaderboard import text
from softbench.leaderboard import verified

DEFAULT_RESULTS = records.DEFAULT_FOLDER
DEFAULT_OUT = pathlib.Path("leaderboard")


def build(
  results: pathlib.Path = DEFAULT_RESULTS, record_filter: filters.RecordFilter | None = None
) -> ranking.Leaderboard:
  """The leaderboard of every record in ``results`` (empty if the folder does not exist), or of
  those ``record_filter`` keeps (every record is checked all the same).

  Raises:
    records.RecordError: a record is malformed or was edited (one line naming the file).
  """
  loaded = records.read_folder(results)
  if record_filter is not None:
    loaded = [(path, record) for path, record in loaded if record_filter.keeps(record)]
  return ranking.rank(loaded, verified.verified(results, loaded))


def write(
  board: ranking.Leaderboard,
  results: pathlib.Path = DEFAULT_RESULTS,
  out: pathlib.Path = DEFAULT_OUT,
) -> list[pathlib.Path]:
  """Writes ``README.md``, ``index.html``, ``leaderboard.csv`` and the performance-profile plots
  of ``board`` into ``out`` (atomically); returns their paths. Links to records and videos are
  relative to ``out``."""
  out = pathlib.Path(out)
  if out.exists() and not out.is_dir():
    raise ValueError(f"{out}: not a folder; --out takes the folder of the pages")
  pages = {
    "README.md": markdown_page.render(board, results, out),
    "index.html": html_page.render(board, results, out),
    csv_table.FILE_NAME: csv_table.render(board, out),
  }
  for name, content in pages.items():
    storage.write_atomically(out / name, content)
  plots_written = []
  for view in aggregate.views(board):
    view.write_profiles(out)
    plots_written.append(out / view.image)
  return [out / name for name in pages] + plots_written


__all__ = ["DEFAULT_OUT", "DEFAULT_RESULTS", "build", "ranking", "records", "text", "write"]
