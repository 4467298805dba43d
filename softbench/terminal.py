"""The command line's terminal: tables for people (rich), which read as plain lines when piped,
JSON documents for scripts, warnings in one line, ``kill`` taken as Ctrl-C, and both held for a
step that must not be cut in two."""

from collections.abc import Collection
from collections.abc import Iterable
from collections.abc import Iterator
from collections.abc import Sequence
import contextlib
import json
import signal
import sys
import threading
import warnings

from rich.console import Console
from rich.console import RenderableType
from rich.table import Table

PIPED_WIDTH = 10_000  # (characters) Line width when stdout is not a terminal: no row wraps.


def table(
  columns: Sequence[str], rows: Iterable[Sequence[str]], right: Collection[str] = ()
) -> Table:
  """``rows`` under the headers ``columns``, in the one table style of softbench: a bold header,
  no borders, columns two spaces apart; the columns named in ``right`` (numbers) right-aligned."""
  shown = Table(box=None, pad_edge=False)
  for column in columns:
    shown.add_column(column, justify="right" if column in right else "left")
  for row in rows:
    shown.add_row(*row)
  return shown


def show(renderable: RenderableType) -> None:
  """Prints ``renderable`` (a table, text, a ``rich.console.Group`` of them) on stdout, text as
  it is (no markup). On a terminal rich fits it to the width; piped, each row is one line without
  trailing spaces."""
  console = Console(file=sys.stdout, markup=False, highlight=False, emoji=False)
  if console.is_terminal:
    console.print(renderable)
    return
  console.width = PIPED_WIDTH
  with console.capture() as captured:
    console.print(renderable)
  print("\n".join(line.rstrip() for line in captured.get().splitlines()))


def print_json(document) -> None:
  """Prints ``document`` as indented JSON (the ``--json`` of a listing); NaN is refused."""
  print(json.dumps(document, indent=2, allow_nan=False))


def one_line_warnings() -> None:
  """Prints warnings as ``softbench: warning: MESSAGE``, without file, line and source."""
  warnings.formatwarning = lambda message, *_, **__: f"softbench: warning: {message}\n"


def _interrupt(signal_number: int, frame) -> None:
  raise KeyboardInterrupt


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
  """Within the block (in the main thread), Ctrl-C and ``kill`` wait for its end and then act as
  they would have: for a step that must not be cut in two (writing a record, and knowing that it
  is written)."""
  if threading.current_thread() is not threading.main_thread():
    yield
    return
  arrived = []
  held = (signal.SIGINT, signal.SIGTERM)
  previous = {
    number: signal.signal(number, lambda number, _: arrived.append(number)) for number in held
  }
  try:
    yield
  finally:
    for number, handler in previous.items():
      signal.signal(number, signal.SIG_DFL if handler is None else handler)  # None: set in C.
  for number in arrived:
    signal.raise_signal(number)


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
  """Within the block (in the main thread), ``kill`` stops softbench as Ctrl-C does: the seed
  workers are terminated rather than left running without their parent."""
  if threading.current_thread() is not threading.main_thread():
    yield
    return
  previous = signal.signal(signal.SIGTERM, _interrupt)
  try:
    yield
  finally:
    signal.signal(signal.SIGTERM, previous)
