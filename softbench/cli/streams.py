"""``softbench streams``: the continual streams and strategies."""

import argparse

from softbench import terminal
from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import robots

  parser.add_argument(
    "--family",
    default="tendon",
    help=f"the tendon family of the configurations shown, one of "
    f"{', '.join(robots.TENDON_FAMILY_NAMES)} (default tendon)",
  )
  parser.add_argument("--json", action="store_true", help=arguments.JSON_HELP)


def handle(args: argparse.Namespace) -> None:
  from softbench.cli import listings
  from softbench.continual import streams

  streams.check_family(args.family)
  if args.json:
    return terminal.print_json(listings.streams_document(args.family))
  terminal.show(listings.streams_table(args.family))


COMMAND = Command("streams", "list the continual streams and strategies", add_arguments, handle)
