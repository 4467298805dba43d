"""``softbench agents``: the registered agents."""

import argparse

from softbench import terminal
from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--verbose", action="store_true", help="also show each learned agent's hyperparameters"
  )
  parser.add_argument(
    "--json", action="store_true", help=arguments.JSON_HELP + ", hyperparameters included"
  )


def handle(args: argparse.Namespace) -> None:
  from softbench.cli import listings

  if args.json:
    return terminal.print_json(listings.agents_document())
  terminal.show(listings.agents_table(args.verbose))


COMMAND = Command("agents", "list the agents", add_arguments, handle)
