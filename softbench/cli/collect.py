"""``softbench collect``: record (or resume) a motor-babbling dataset."""

import argparse

from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import data

  parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument(
    "--samples",
    type=int,
    default=data.DEFAULT_SAMPLES,
    help=f"control periods to record (default {data.DEFAULT_SAMPLES})",
  )
  parser.add_argument("--seed", type=int, default=0, help="seed of the random actions")
  parser.add_argument(
    "--workers", type=int, default=None, help="simulation threads (default: every core)"
  )


def handle(args: argparse.Namespace) -> None:
  from softbench import data

  collected = data.collect(args.robot, samples=args.samples, seed=args.seed, workers=args.workers)
  print(collected.describe())
  print(collected.path)


COMMAND = Command(
  "collect",
  "record (or resume) a motor-babbling dataset",
  add_arguments,
  handle,
  "Motor babbling with every module active, cached under $SOFTBENCH_HOME "
  "(default $XDG_CACHE_HOME/softbench, or ~/.cache/softbench); an interrupted "
  "collection resumes.",
  caches=True,
)
