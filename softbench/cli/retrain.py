"""``softbench retrain``: the faulty module's SMPL column retrained after an actuator fault."""

import argparse
import pathlib

from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench.runners import retrain as retrain_module

  parser.add_argument(
    "--agent",
    default=retrain_module.RETRAINED_AGENT,
    help="the agent to adapt (smpl, the default, is the only one)",
  )
  parser.add_argument("--robot", help="default: the task's robot in the paper")
  parser.add_argument(
    "--fault",
    action="append",
    default=[],
    help=arguments.FAULT_HELP + "; every fault in one module",
  )
  parser.add_argument(
    "--task", default=retrain_module.DEFAULT_TASK, help=f"default {retrain_module.DEFAULT_TASK}"
  )
  parser.add_argument(
    "--baseline",
    default=retrain_module.DEFAULT_BASELINE,
    help=f"centralised baseline retrained from scratch (default {retrain_module.DEFAULT_BASELINE})",
  )
  parser.add_argument("--seeds", type=int, help=arguments.SEEDS_HELP)
  arguments.add_profile_argument(parser)
  arguments.add_record_arguments(parser)


def handle(args: argparse.Namespace) -> None:
  from softbench.runners import retrain as retrain_module
  from softbench.runners import saving

  settings = retrain_module.settings(
    args.agent, args.robot, tuple(args.fault), args.profile, args.task, args.seeds, args.baseline
  )
  arguments.check_record_arguments(args)
  record = retrain_module.execute(settings)
  saving.save(retrain_module, record, pathlib.Path(args.results), arguments.json_copy(args))


COMMAND = Command(
  "retrain",
  "retrain the faulty module's SMPL column after an actuator fault",
  add_arguments,
  handle,
  "Collects babbling on the faulty robot, retrains only the faulty module's "
  "column of the smpl agent (and the forward models from that module on), and "
  "compares the errors before the fault, under it, after retraining one column "
  "and of a centralised baseline retrained from scratch, with wall times.",
  caches=True,
  uses_zoo=True,
)
