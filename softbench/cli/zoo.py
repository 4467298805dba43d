"""``softbench zoo``: the trained weights kept in the repository; list, add, remove, verify."""

import argparse
import pathlib

from softbench import profiles
from softbench import terminal
from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import zoo

  zoo_commands = parser.add_subparsers(dest="zoo_command", required=True)
  for name, add_own_arguments, handler, summary, description in _SUBCOMMANDS:
    subparser = zoo_commands.add_parser(name, help=summary, description=description)
    add_own_arguments(subparser)
    subparser.add_argument(
      "--zoo", help=f"the zoo folder (default ${zoo.VARIABLE}, else zoo/ of the checkout)"
    )
    subparser.set_defaults(run=handler)


def _add_arguments_to_add(parser: argparse.ArgumentParser) -> None:
  _add_setting_arguments(parser)
  arguments.add_results_argument(parser, "folder of the records to link")
  parser.add_argument(
    "--link-unchecked",
    action="store_true",
    help="also link the setting's records that name no weights (made before records named "
    "them); check them with softbench zoo verify",
  )


def _add_arguments_to_verify(parser: argparse.ArgumentParser) -> None:
  parser.add_argument("--agents", nargs="+", metavar="AGENT", help="only these agents")
  parser.add_argument("--quick", action="store_true", help="seed 0 only, one record per checkpoint")
  arguments.add_results_argument(parser, "folder of the records to verify")


def _add_setting_arguments(parser: argparse.ArgumentParser) -> None:
  """The setting of ``zoo add`` and ``zoo remove``: an agent on a robot, or Exp1S on a family."""
  from softbench import robots
  from softbench.records import exp1s as exp1s_records

  parser.add_argument("--agent", help="a learned agent")
  parser.add_argument("--robot", help="the robot it was trained on")
  parser.add_argument("--protocol", help=f"{exp1s_records.PROTOCOL}: the Exp1S networks instead")
  parser.add_argument(
    "--family",
    help=(
      f"with --protocol {exp1s_records.PROTOCOL}: one of {', '.join(robots.TENDON_FAMILY_NAMES)}"
    ),
  )
  parser.add_argument(
    "--seeds",
    type=int,
    help=f"seeds 0 .. N-1, N at most {profiles.MAX_SEEDS:,} (default: the profile's)",
  )
  parser.add_argument(
    "--seed",
    type=int,
    action="append",
    default=[],
    help="seed K alone instead (repeat for several): e.g. to carry some trainings under way "
    "within the zoo's budget",
  )
  arguments.add_profile_argument(parser)


def _chosen_setting(args: argparse.Namespace):
  """The setting that ``_add_setting_arguments``'s flags name, checked."""
  from softbench.runners import zoo_catalogue

  return zoo_catalogue.requested_setting(
    args.agent, args.robot, args.protocol, args.family, args.profile, args.seeds, args.seed
  )


def _list(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.zoo import listing as zoo_listing

  terminal.show(zoo_listing.contents(zoo.chosen_folder(args.zoo)))


def _add(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_catalogue
  from softbench.zoo import listing as zoo_listing

  chosen = _chosen_setting(args)
  folder = zoo.chosen_folder(args.zoo, create=True)
  added, skipped, unchecked = zoo_catalogue.add(
    chosen, pathlib.Path(args.results), folder, args.link_unchecked
  )
  print(zoo_listing.additions(added, skipped, folder, unchecked))


def _remove(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_catalogue
  from softbench.zoo import listing as zoo_listing

  chosen = _chosen_setting(args)
  folder = zoo.chosen_folder(args.zoo)
  print(zoo_listing.removals(zoo_catalogue.remove(chosen, folder), folder))


def _verify(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_verification

  zoo_verification.verify_zoo(
    pathlib.Path(args.results),
    zoo.chosen_folder(args.zoo),
    tuple(args.agents) if args.agents else None,
    args.quick,
  )


# Each subcommand: its name, the function that adds its arguments (all but --zoo, which every one
# takes last), its handler, its line in ``softbench zoo --help`` and its description.
_SUBCOMMANDS = (
  ("list", lambda parser: None, _list, "the zoo's files, sizes and records", None),
  (
    "add",
    _add_arguments_to_add,
    _add,
    "copy a setting's finished weights into the zoo",
    "Copies each seed's finished checkpoint and forward models from the data home into the "
    "zoo (never an unfinished training's state), and links the records in --results that "
    "they made: those whose weights section names these files' sha256.",
  ),
  (
    "remove",
    _add_setting_arguments,
    _remove,
    "remove a setting's weights from the zoo",
    "Removes each seed's checkpoint and the forward models that no other agent in the zoo reads.",
  ),
  (
    "verify",
    _add_arguments_to_verify,
    _verify,
    "re-score records from the zoo alone and compare them",
    "Re-scores, in an empty data home, every record the zoo's agents stand "
    "behind, seed by seed, and compares each figure with the record's.",
  ),
)


COMMAND = Command(
  "zoo",
  "trained weights kept in the repository: list, add, verify",
  add_arguments,
  None,
  "The zoo holds the finished weights behind leaderboard records; softbench run takes them "
  "instead of training.",
)
