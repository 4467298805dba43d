"""``softbench tasks``: the tasks of the suite."""

import argparse

from softbench import terminal
from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument("--json", action="store_true", help=arguments.JSON_HELP)


def handle(args: argparse.Namespace) -> None:
  from softbench.cli import listings

  if args.json:
    return terminal.print_json(listings.tasks_document())
  terminal.show(listings.tasks_table())


COMMAND = Command("tasks", "list the tasks of the suite", add_arguments, handle)
