"""The command line's argument parser: one line for a malformed command line."""

import argparse
import difflib

from softbench.cli import errors


class OneLineErrorParser(argparse.ArgumentParser):
  """An argument parser (and, through ``add_subparsers``, its subcommands' parsers) whose
  command-line errors are one line, pointing at the command's own ``--help`` (and at the option
  meant, for a misspelt one) instead of printing the usage. Options are never abbreviated: run's
  ``--seeds N`` (a count) must not answer to render's ``--seed K`` (which seed)."""

  def __init__(self, *args, **kwargs):
    super().__init__(*args, allow_abbrev=False, **kwargs)
    self.command_parsers: dict[str, "OneLineErrorParser"] = {}

  def error(self, message: str):
    self.exit(errors.EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

  def parse_args(self, args=None, namespace=None):
    """Parses like ``argparse``, but an argument no parser took is the command's error."""
    parsed, unknown = self.parse_known_args(args, namespace)
    if unknown:
      command = self.command_parsers.get(getattr(parsed, "command", None), self)
      command.error(f"unrecognized arguments: {' '.join(unknown)}{command.suggestion(unknown)}")
    return parsed

  def suggestion(self, unknown: list[str]) -> str:
    """'; did you mean --seeds?' for the first unknown option close to one of this parser's."""
    known = [option for action in self._actions for option in action.option_strings]
    for word in unknown:
      close = difflib.get_close_matches(word.partition("=")[0], known, n=1, cutoff=0.75)
      if word.startswith("--") and close:
        return f"; did you mean {close[0]}?"
    return ""


def command_named(argv: list[str]) -> str | None:
  """The command ``argv`` names: its first word that is not an option (softbench's own options,
  ``--help`` and ``--version``, take no value)."""
  return next((word for word in argv if not word.startswith("-")), None)
