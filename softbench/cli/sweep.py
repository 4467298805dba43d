"""``softbench sweep``: a grid of robots, tasks and agents (and Exp1S) as Ray tasks."""

import argparse

from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import robots
  from softbench import suite
  from softbench.continual import streams
  from softbench.records import continual as continual_records
  from softbench.records import exp1s as exp1s_records

  parser.add_argument(
    "--robots", nargs="+", default=[], metavar="ROBOT", help="e.g. tendon-1 tendon-3"
  )
  parser.add_argument(
    "--tasks", nargs="+", default=[], metavar="TASK", help=f"of {', '.join(suite.TASKS)}"
  )
  parser.add_argument(
    "--agents", nargs="+", default=[], metavar="AGENT", help=f"of {', '.join(agents.AGENTS)}"
  )
  parser.add_argument(
    "--protocol",
    help=f"{exp1s_records.PROTOCOL}: also SMPL's Exp1S on each of --families (then --robots, "
    f"--tasks and --agents may be left out); {continual_records.PROTOCOL}: each continual "
    f"strategy of --agents on each of --streams and --families, and nothing else",
  )
  parser.add_argument(
    "--streams",
    nargs="+",
    metavar="STREAM",
    help=f"with --protocol {continual_records.PROTOCOL}: of {', '.join(streams.STREAMS)}",
  )
  parser.add_argument(
    "--families",
    nargs="+",
    metavar="FAMILY",
    help=f"with --protocol {exp1s_records.PROTOCOL} or {continual_records.PROTOCOL}: of "
    f"{', '.join(robots.TENDON_FAMILY_NAMES)} (default {exp1s_records.DEFAULT_FAMILY})",
  )
  arguments.add_profile_argument(parser)
  parser.add_argument("--seeds", type=int, help=arguments.SEEDS_HELP)
  parser.add_argument(
    "--eval",
    nargs="+",
    default=["physics"],
    metavar="MODE",
    help="the error fed back: physics (default), model, open-loop; several: a setting each",
  )
  parser.add_argument(
    "--address",
    help="HOST:PORT of a Ray cluster's head (ray start --head); default: a local Ray",
  )
  parser.add_argument(
    "--data-home",
    help="the data home of this machine and every worker, e.g. on shared storage "
    "(default: $SOFTBENCH_HOME)",
  )
  arguments.add_results_argument(parser)
  arguments.add_physics_argument(parser)
  parser.add_argument(
    "--dry-run",
    action="store_true",
    help="print the settings that have no record yet and what they need built; run nothing",
  )


def handle(args: argparse.Namespace) -> None:
  from softbench.records import continual as continual_records
  from softbench.runners import continual

  arguments.check_physics(args)
  if args.protocol is None and args.families is not None:
    raise ValueError(f"--families goes with --protocol {continual.PROTOCOL}")
  if args.streams is not None and args.protocol != continual_records.PROTOCOL:
    raise ValueError(f"--streams goes with --protocol {continual_records.PROTOCOL}")
  if args.protocol == continual_records.PROTOCOL:
    if not args.streams:
      raise ValueError(f"--protocol {continual_records.PROTOCOL} needs --streams STREAM ...")
    if args.robots or args.tasks:
      raise ValueError(
        f"--protocol {continual_records.PROTOCOL} runs strategies on streams; drop --robots "
        f"and --tasks (--agents names the strategies)"
      )
    return _sweep(args, (), args.streams, args.agents)
  if args.protocol is not None:
    continual.settings(args.protocol, "smpl")  # An unknown protocol: its one line.
  _sweep(args, args.agents)


def _sweep(args: argparse.Namespace, agents, streams=(), strategies=()) -> None:
  from softbench import sweep
  from softbench.runners import continual

  sweep.sweep(
    args.robots,
    args.tasks,
    agents,
    args.results,
    args.profile,
    args.seeds,
    args.eval,
    args.address,
    args.data_home,
    families=(args.families or [continual.DEFAULT_FAMILY]) if args.protocol else (),
    dry_run=args.dry_run,
    streams=streams,
    strategies=strategies,
  )


COMMAND = Command(
  "sweep",
  "run a grid of robots, tasks and agents (and Exp1S) as Ray tasks, here or on a cluster",
  add_arguments,
  handle,
  "Runs every setting (robot, task, agent, eval mode; with --protocol exp1s, "
  "Exp1S on each of --families; with --protocol continual, each strategy on each of "
  "--streams) that --results has no record of for the profile, as Ray "
  "tasks: each babbling dataset, forward model, agent and Exp1S network is built once and "
  "shared, and each record is the one softbench run writes. Without --address, on a local "
  "Ray with one worker per core; docs/sweep.md for a cluster.",
  uses_zoo=True,
)
