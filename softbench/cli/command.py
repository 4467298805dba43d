"""What a command of the command line is: each command's module declares one as ``COMMAND``."""

import argparse
from collections.abc import Callable
import dataclasses

from softbench import storage
from softbench import zoo


@dataclasses.dataclass(frozen=True)
class Command:
  """A command: its name, its line in ``softbench --help``, the function that adds its arguments
  (and imports what their help names), the handler that runs it (None where its own subcommands
  name theirs), its description in ``softbench COMMAND --help``, and whether it writes to the
  data home (``caches``) or takes trained weights from the zoo (``uses_zoo``)."""

  name: str
  help: str
  add_arguments: Callable[[argparse.ArgumentParser], None]
  handle: Callable[[argparse.Namespace], None] | None
  description: str | None = None
  caches: bool = False
  uses_zoo: bool = False

  def run(self, args: argparse.Namespace) -> None:
    """Runs ``args``'s handler (this command's or its subcommand's) after the checks that must
    come before any work."""
    if self.caches:  # A home that takes no file fails at once, not after the first seed.
      storage.check_home()
    if self.uses_zoo:
      zoo.folder()  # A $SOFTBENCH_ZOO that names no folder: refused before any work.
    args.run(args)
