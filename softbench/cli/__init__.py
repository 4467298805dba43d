"""The ``softbench`` command line. It parses arguments and calls the library; a bad input gets
one line on stderr and exit code 2, a malformed command line included.

Each command is a module of this package that declares its ``COMMAND``: its arguments and its
handler. Only the command that runs has its arguments built, and a command's arguments and handler
import the modules they need themselves: ``softbench --help`` and the listings start without
loading torch, Ray or the plotting stack (6 s here, when every command's modules were imported).
``parsing.py`` holds the parser, ``errors.py`` the exit codes, and ``arguments.py`` the arguments
that several commands share."""

import argparse
from collections.abc import Collection
import sys
import warnings

import softbench
from softbench import terminal
from softbench.cli import agents
from softbench.cli import collect
from softbench.cli import errors
from softbench.cli import leaderboard
from softbench.cli import models
from softbench.cli import parsing
from softbench.cli import render
from softbench.cli import retrain
from softbench.cli import robots
from softbench.cli import run
from softbench.cli import streams
from softbench.cli import sweep
from softbench.cli import tasks
from softbench.cli import tune
from softbench.cli import zoo
from softbench.cli.errors import EXIT_FAILURE
from softbench.cli.errors import EXIT_INTERRUPTED
from softbench.cli.errors import EXIT_USAGE

# The commands in the order of ``softbench --help``.
_COMMANDS = {
  module.COMMAND.name: module.COMMAND
  for module in (
    robots,
    tasks,
    collect,
    agents,
    streams,
    tune,
    run,
    sweep,
    leaderboard,
    render,
    retrain,
    zoo,
    models,
  )
}


def build_parser(commands: Collection[str] = tuple(_COMMANDS)) -> argparse.ArgumentParser:
  """The command line's parser, with the arguments of ``commands`` (default: every command's;
  the others keep their line in ``softbench --help``, and their modules stay unimported)."""
  parser = parsing.OneLineErrorParser(prog="softbench", description=__doc__.split(".")[0] + ".")
  parser.add_argument("--version", action="version", version=f"softbench {softbench.__version__}")
  subparsers = parser.add_subparsers(dest="command", required=True)
  for name, command in _COMMANDS.items():
    command_parser = subparsers.add_parser(name, help=command.help, description=command.description)
    parser.command_parsers[name] = command_parser
    if name in commands:
      command.add_arguments(command_parser)
      if command.handle is not None:
        command_parser.set_defaults(run=command.handle)
  return parser


def _warn_of_left_out_agents() -> None:
  """A one-line warning per agent of an installed package that could not be registered, where
  this command loaded the registry (``agents.LEFT_OUT``)."""
  registry = sys.modules.get("softbench.agents")
  for message in getattr(registry, "LEFT_OUT", {}).values():
    warnings.warn(message, RuntimeWarning, stacklevel=1)


def main(argv: list[str] | None = None) -> int:
  argv = sys.argv[1:] if argv is None else argv
  try:
    named = parsing.command_named(argv)
    args = build_parser([named] if named else []).parse_args(argv)
  except SystemExit as done:  # --help (0), or a malformed command line (one line, 2).
    return done.code
  terminal.one_line_warnings()
  _warn_of_left_out_agents()

  def work() -> None:
    with terminal.sigterm_as_interrupt():
      _COMMANDS[args.command].run(args)

  return errors.exit_code(work)


__all__ = ["EXIT_FAILURE", "EXIT_INTERRUPTED", "EXIT_USAGE", "build_parser", "main"]
