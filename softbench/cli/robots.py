"""``softbench robots``: the registered robots, or one described."""

import argparse

from softbench import terminal
from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument("name", nargs="?", help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument("--module-length", type=float, help="module length in m")
  parser.add_argument("--json", action="store_true", help=arguments.JSON_HELP)


def _robot_overrides(args: argparse.Namespace) -> dict:
  return {"module_length": args.module_length} if args.module_length is not None else {}


def handle(args: argparse.Namespace) -> None:
  from softbench.cli import listings

  if args.json:
    return terminal.print_json(listings.robots_document(args.name, **_robot_overrides(args)))
  terminal.show(listings.robots_table(args.name, **_robot_overrides(args)))


COMMAND = Command("robots", "list the registered robots or describe one", add_arguments, handle)
