"""``softbench leaderboard``: the result records ranked per robot and task."""

import argparse
import pathlib

from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import leaderboard
  from softbench.leaderboard import grid

  arguments.add_results_argument(parser)
  parser.add_argument(
    "--write",
    action="store_true",
    help="also regenerate README.md and index.html in --out, and the "
    "results tables of the checkout's README.md and docs/*.md",
  )
  parser.add_argument(
    "--out",
    default=str(leaderboard.DEFAULT_OUT),
    help=f"folder of the pages (default {leaderboard.DEFAULT_OUT})",
  )
  parser.add_argument(
    "--grid",
    choices=tuple(grid.lists()),
    help="print the names on one axis of the grid make leaderboard fills, and nothing else",
  )
  for axis, metavar, what, example in (
    ("robots", "ROBOT", "robots", "tendon-3"),
    ("tasks", "TASK", "tasks", "reach"),
    ("agents", "AGENT", "agents", "smpl lstm"),
    ("profiles", "PROFILE", "profiles", "paper"),
    ("physics", "VERSION", "physics versions", "v0"),
  ):
    parser.add_argument(
      f"--{axis}",
      nargs="+",
      metavar=metavar,
      help=f"print only the records of these {what}, e.g. {example}",
    )


def handle(args: argparse.Namespace) -> None:
  from softbench import leaderboard
  from softbench.leaderboard import doc_pages
  from softbench.leaderboard import filters
  from softbench.leaderboard import grid

  if args.grid is not None:
    print(" ".join(grid.lists()[args.grid]))
    return
  results = pathlib.Path(args.results)
  if not results.exists():  # A mistyped folder is no empty leaderboard.
    raise ValueError(f"no folder of result records at {results}")
  record_filter = filters.RecordFilter(
    *(
      tuple(names or ())
      for names in (args.robots, args.tasks, args.agents, args.profiles, args.physics)
    )
  )
  if args.write and record_filter.active:
    raise ValueError(
      "--write writes the whole leaderboard; drop --robots, --tasks, --agents, --profiles and "
      "--physics"
    )
  board = leaderboard.build(results, record_filter)
  print(leaderboard.text.report(board, results, record_filter.describe()))
  if args.write:
    for path in [
      *leaderboard.write(board, results, pathlib.Path(args.out)),
      *doc_pages.write(board, results),
    ]:
      print(f"wrote {path}")


COMMAND = Command(
  "leaderboard",
  "rank the result records per robot and task",
  add_arguments,
  handle,
  "Checks every result record (schema and integrity hash) and prints, per robot "
  "and task, the newest record of each agent, profile and eval mode, ranked by "
  "position error: mean ± std over seeds [95% bootstrap CI].",
)
