"""``softbench models export``: the robots' MJCF models written to a folder."""

import argparse

from softbench import storage
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  models_commands = parser.add_subparsers(dest="models_command", required=True)
  export_parser = models_commands.add_parser("export", help="write models/<name>/ for every robot")
  export_parser.add_argument("--out", default="models", help="output folder (default: models)")
  export_parser.add_argument(
    "--robots",
    nargs="+",
    metavar="ROBOT",
    help="export only these robots (default: every registered robot)",
  )
  export_parser.add_argument(
    "--measure-speed", action="store_true", help="also measure simulation speed into speed.json"
  )
  export_parser.set_defaults(run=_export)


def _export(args: argparse.Namespace) -> None:
  from softbench import robots
  from softbench.robots import export as model_export

  out = storage.check_writable(args.out, "models to", folder=True)
  chosen = [robots.make(name) for name in args.robots or robots.REGISTERED_ROBOTS]  # Checked first.
  for robot in chosen:
    for path in model_export.export(robot, out, args.measure_speed):
      print(path)


COMMAND = Command("models", "exported MJCF models", add_arguments, None)
