"""``softbench tune``: an Optuna study of a learned agent's hyperparameters."""

import argparse

from softbench import profiles
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import tuning

  parser.add_argument("--agent", required=True, help="a learned agent, e.g. smpl or lstm")
  parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument(
    "--trials",
    type=int,
    default=tuning.DEFAULT_TRIALS,
    help=f"finished trials the study should hold, at most {tuning.MAX_TRIALS:,} (default "
    f"{tuning.DEFAULT_TRIALS}); re-running adds the missing ones",
  )
  parser.add_argument(
    "--storage", help="Optuna storage URL (default: sqlite:///$SOFTBENCH_HOME/tuning.db)"
  )
  parser.add_argument(
    "--profile",
    default=profiles.DEFAULT_PROFILE,
    help=f"data and epoch budget: one of {', '.join(profiles.PROFILES)} "
    f"(default {profiles.DEFAULT_PROFILE})",
  )
  parser.add_argument(
    "--epochs",
    type=int,
    help="epoch budget of each trial's inverse model (default: the "
    "profile's; fewer buys more trials)",
  )
  parser.add_argument("--study", help="study name (default AGENT-ROBOT-PROFILE)")
  parser.add_argument(
    "--summary", help="where to write the study summary (default $SOFTBENCH_HOME/tuning/STUDY.json)"
  )
  parser.add_argument(
    "--confirm",
    action="store_true",
    help="then train the previous and the best values at the profile's "
    "full epoch budget and report both",
  )
  parser.add_argument(
    "--adopt",
    action="store_true",
    help="commit the best values as the agent's hyperparameters on the "
    "robot (softbench/agents/hyperparameters.json)",
  )


def handle(args: argparse.Namespace) -> None:
  from softbench import tuning

  settings = tuning.settings(
    args.agent, args.robot, args.trials, args.storage, args.profile, args.study, args.epochs
  )
  tuning.tune(settings, args.confirm, args.summary, args.adopt)


COMMAND = Command(
  "tune",
  "tune a learned agent's hyperparameters with Optuna",
  add_arguments,
  handle,
  "Runs (or resumes) an Optuna study of the agent's hyperparameters on the "
  "babbling validation split; the same budget for every agent.",
  caches=True,
)
