"""The generated tables in the documentation (``README.md``, ``docs/*.md``), kept up to date.

A page holds a generated table between two marker lines::

  <!-- softbench:table NAME -->
  ...
  <!-- /softbench:table -->

NAME is one of ``doc_tables.TABLES``. ``NAME@vN`` builds it from the records of
physics version vN (``softbench.robots.versions``; ``ranking.Leaderboard.of_physics``), NAME alone
from the current physics' records; the block holds it as the leaderboard's
markdown page renders tables (``markdown_page.table_lines``). Every figure is the leaderboard's:
mean ± standard deviation over seeds (population, ddof 0) of the newest record of each setting.
``softbench leaderboard --write`` rewrites the blocks (``write``), and a test checks that every
block is known and up to date (``stale_blocks``), so that no table drifts from the records. No
table shows a figure that changes from machine to machine (wall times are the page's), and a
figure re-scored on another kind of CPU is up to date within one unit of its last digit.
"""

import dataclasses
import pathlib
import re

from softbench import storage
from softbench.leaderboard import markdown_page
from softbench.leaderboard import ranking
from softbench.leaderboard.doc_tables import TABLES
from softbench.leaderboard.doc_tables import DocTableError
from softbench.robots import versions

START = re.compile(r"^<!-- softbench:table (?P<name>\S+) -->$")
END = "<!-- /softbench:table -->"
DOCS = "docs"  # Beside README.md in the checkout that holds the records (``pages``).
NUMBER = re.compile(r"\d[\d,]*(?:\.\d+)?")  # A figure in a table: 1,234.56.
RESCORE_UNITS = 1  # How far a shown figure may be off in its last digit (``same_figures``).


PHYSICS_SEPARATOR = "@"  # NAME@v0: table NAME of the records of physics v0.


def _table_and_physics(name: str) -> tuple[str, str | None]:
  """(table, physics version or None) of a block name; raises DocTableError for an unknown
  table or physics version."""
  table, _, physics = name.partition(PHYSICS_SEPARATOR)
  if table not in TABLES:
    raise DocTableError(f"unknown table {table!r}; known: {', '.join(TABLES)}")
  if physics:
    try:
      versions.named(physics)
    except ValueError as error:
      raise DocTableError(f"{error} (table {name!r})") from None
  return table, physics or None


def render(name: str, board: ranking.Leaderboard) -> str:
  """The markdown of table ``name`` (its caption, then the table; ``NAME@vN`` of physics vN's
  records), ending in a newline."""
  table, physics = _table_and_physics(name)
  shown = board if physics is None else board.of_physics(physics)
  return "\n".join(markdown_page.table_lines(TABLES[table](shown)))


@dataclasses.dataclass(frozen=True)
class Block:
  """A generated table in a page: its name and lines [start, end) between the markers."""

  name: str
  start: int  # The line after the opening marker (0-based).
  end: int  # The closing marker's line.


def blocks(text: str, page: str = "page") -> list[Block]:
  """The table blocks of a page's ``text``.

  Raises:
    DocTableError: an unknown name, a block left open, nested, or closed without opening.
  """
  found, opened = [], None
  lines = text.split("\n")
  for number, line in enumerate(lines):
    start = START.match(line)
    if start:
      if opened is not None:
        raise DocTableError(f"{page}:{number + 1}: table block inside block {opened[0]!r}")
      try:
        _table_and_physics(start["name"])
      except DocTableError as error:
        raise DocTableError(f"{page}:{number + 1}: {error}") from None
      opened = start["name"], number + 1
    elif line == END:
      if opened is None:
        raise DocTableError(f"{page}:{number + 1}: {END} without an opening marker")
      found.append(Block(opened[0], opened[1], number))
      opened = None
  if opened is not None:
    raise DocTableError(f"{page}:{opened[1]}: table block {opened[0]!r} is never closed")
  return found


def _body(lines: list[str], block: Block) -> str:
  return "".join(line + "\n" for line in lines[block.start : block.end])


def same_figures(shown: str, generated: str) -> bool:
  """Whether a table as a page shows it and as the records generate it agree: the same text but
  for numbers that differ by at most ``RESCORE_UNITS`` in their last digit shown. A record
  re-scored on another kind of CPU differs from the committed one from the 8th significant digit
  on (docs/physics-versions.md), which can flip a rounding, never more."""
  shown_numbers, generated_numbers = NUMBER.findall(shown), NUMBER.findall(generated)
  if NUMBER.split(shown) != NUMBER.split(generated) or len(shown_numbers) != len(generated_numbers):
    return False
  for first, second in zip(shown_numbers, generated_numbers):
    decimals = len(first.partition(".")[2])
    if first == second:
      continue
    if decimals != len(second.partition(".")[2]):
      return False
    difference = abs(float(first.replace(",", "")) - float(second.replace(",", "")))
    if difference > RESCORE_UNITS * 10.0**-decimals * (1 + 1e-9):
      return False
  return True


def stale_blocks(text: str, board: ranking.Leaderboard, page: str = "page") -> list[str]:
  """The names of the blocks of ``text`` whose figures differ from what ``board`` generates
  (``same_figures``)."""
  lines = text.split("\n")
  return [
    block.name
    for block in blocks(text, page)
    if not same_figures(_body(lines, block), render(block.name, board))
  ]


def rewrite(text: str, board: ranking.Leaderboard, page: str = "page") -> str:
  """``text`` with every table block generated again from ``board``."""
  lines, parts, done = text.split("\n"), [], 0
  for block in blocks(text, page):
    parts += lines[done : block.start] + render(block.name, board).split("\n")[:-1]
    done = block.end
  return "\n".join(parts + lines[done:])


def pages(results: pathlib.Path) -> list[pathlib.Path]:
  """The documentation pages of the checkout whose records ``results`` is (its
  ``leaderboard/results``): ``README.md`` and ``docs/*.md``; none for another folder."""
  results = pathlib.Path(results).resolve()
  if results.parts[-2:] != ("leaderboard", "results"):
    return []
  root = results.parent.parent
  readme = [root / "README.md"] if (root / "README.md").is_file() else []
  return readme + sorted((root / DOCS).glob("*.md"))


def write(board: ranking.Leaderboard, results: pathlib.Path) -> list[pathlib.Path]:
  """Rewrites, atomically, the table blocks of the documentation pages of ``results``
  (``pages``) that differ from ``board``'s; returns the pages written."""
  written = []
  for page in pages(results):
    text = page.read_text(encoding="utf-8")
    new = rewrite(text, board, str(page))
    if new != text:
      storage.write_atomically(page, new)
      written.append(page)
  return written
