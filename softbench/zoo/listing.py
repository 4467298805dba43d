"""What ``softbench zoo list``, ``zoo add`` and ``zoo remove`` print: the zoo's files as a table,
what was added or removed, and how much of its budget the zoo holds."""

import pathlib

from rich.console import Group
from rich.console import RenderableType

from softbench import terminal
from softbench import zoo

KB = 10**3  # (bytes) A kilobyte.


def usage(folder: pathlib.Path, entries: dict[str, zoo.ZooFile]) -> str:
  """``1.2 MB of 100 MB (FOLDER)``: what ``entries`` (the zoo ``folder``'s) hold of its
  budget."""
  return (
    f"{zoo.size_bytes(entries) / zoo.MB:.1f} MB of {zoo.BUDGET_BYTES / zoo.MB:.0f} MB ({folder})"
  )


def contents(folder: pathlib.Path) -> RenderableType:
  """The zoo's files (kind, physics version, size, records, path), how much they hold, then any
  problem of a file against the manifest."""
  entries = zoo.read_manifest(folder)
  rows = [
    [entry.kind, entry.physics, f"{entry.bytes / KB:.1f}", str(len(entry.records)), path]
    for path, entry in sorted(entries.items())
  ]
  return Group(
    terminal.table(("kind", "physics", "kB", "records", "path"), rows, right=("kB", "records")),
    f"{len(entries)} files, {usage(folder, entries)}",
    *(f"problem: {problem}" for problem in zoo.check_files(folder)),
  )


def additions(
  added: list[zoo.ZooFile],
  skipped: list[pathlib.Path],
  folder: pathlib.Path,
  unchecked: list[str] = (),
) -> str:
  """What ``zoo.add`` did (its ``added`` entries and ``skipped`` cache files), the records left
  unlinked because they name no weights (``unchecked``), then how much the zoo ``folder`` holds
  now; one fact a line."""
  lines = [
    f"added {entry.path} ({entry.kind}, {entry.bytes / KB:.1f} kB, {len(entry.records)} records)"
    for entry in added
  ]
  lines += [
    f"skipped {path.name}: its training has not started in the data home" for path in skipped
  ]
  lines += [
    f"not linked {name}: it names no weights (made before records did); --link-unchecked "
    f"links it, softbench zoo verify checks it"
    for name in unchecked
  ]
  lines.append(f"zoo: {usage(folder, zoo.read_manifest(folder))}")
  return "\n".join(lines)


def removals(removed: list[zoo.ZooFile], folder: pathlib.Path) -> str:
  """What ``zoo.remove`` removed, then how much the zoo ``folder`` holds now; one fact a line."""
  lines = [f"removed {entry.path} ({entry.kind}, {entry.bytes / KB:.1f} kB)" for entry in removed]
  lines.append(f"zoo: {usage(folder, zoo.read_manifest(folder))}")
  return "\n".join(lines)
