"""The zoo: finished trained weights kept in the repository, so that a fresh clone re-scores a
record without training.

``zoo/`` holds files laid out as in the data home, each under the path the cache looks for:

- ``checkpoints/KEY.pt``: a trained agent (an Exp2S agent or an Exp1S network), weights only;
- ``forward/KEY.pt``: a frozen forward model, shared by the agents that read its view.

Never the state of an unfinished training (``KEY.partial/``, optimiser included): it is replaced
at every save, and each one committed stays in the history for good (162 MB of BiLSTM training
states did). An interrupted training resumes from the data home it ran in (docs/layout.md).

``zoo/manifest.json`` lists every file with its sha256, size, kind, the cache key it answers (and
the configuration stored in it) and the records it stands behind. Before the cache trains a model
it asks the zoo (``restore``): a file the data home lacks is copied in, after its sha256 is
checked, with one line on stderr; a damaged or tampered file is refused with one warning and the
model is trained instead. Everything else (checking the configuration, the weights' own hash) is
the cache's usual loading.

The zoo is ``$SOFTBENCH_ZOO`` if set (``none`` turns it off; anything else but a folder is
refused), else the ``zoo/`` folder of the source checkout softbench runs from (``chosen_folder``:
the one a ``softbench zoo`` command works on). Which records each file stands behind, and
re-scoring them from the zoo alone, belong to the runners (``runners.zoo_catalogue``,
``runners.zoo_verification``); what ``softbench zoo list`` and ``zoo add`` print, to
``zoo.listing``.
"""

import dataclasses
import hashlib
import json
import os
import pathlib
import sys
import warnings

from smpl.files import first_line
from softbench import storage

VARIABLE = "SOFTBENCH_ZOO"
OFF = "none"
MANIFEST = "manifest.json"
FORMAT = "softbench-zoo"
VERSION = 1
KINDS = ("agent", "forward")
MB = 10**6  # (bytes) A megabyte, as the zoo's sizes are given.
BUDGET_BYTES = 100 * MB  # (bytes) What the repository's zoo may hold in all: 100 MB.
_REPOSITORY_ZOO = pathlib.Path(__file__).resolve().parents[2] / "zoo"  # Of a source checkout.


class ZooWarning(UserWarning):
  """A zoo file or manifest that cannot be used; the model is trained instead."""


@dataclasses.dataclass(frozen=True)
class ZooFile:
  """One file of the zoo; ``path`` is relative to the zoo and to the data home alike."""

  path: str
  sha256: str
  bytes: int
  kind: str
  key: str  # The cache key the file answers (a checkpoint's file name without .pt).
  config: dict = dataclasses.field(default_factory=dict)  # As stored in the checkpoint.
  records: tuple[str, ...] = ()  # File names of the records it stands behind.
  physics: str = "v0"  # The physics version it was trained on (softbench.robots.versions);
  # entries made before versions (2026-12-06) lack the field and are v0.

  def to_json(self) -> dict:
    return {**dataclasses.asdict(self), "records": list(self.records)}


def location() -> pathlib.Path | None:
  """Where the zoo is, whether or not it exists yet: ``$SOFTBENCH_ZOO``, else ``zoo/`` of the
  checkout; None when ``$SOFTBENCH_ZOO`` is ``none``."""
  chosen = os.environ.get(VARIABLE)
  if chosen == OFF:
    return None
  return pathlib.Path(chosen).expanduser() if chosen else _REPOSITORY_ZOO


def folder() -> pathlib.Path | None:
  """The zoo in use: ``location()`` if it is a folder, else None (turned off, or no checkout's
  ``zoo/``).

  Raises:
    ValueError: ``$SOFTBENCH_ZOO`` names something other than a folder (one line naming the
      variable: a zoo named and not used would train what it holds, silently).
  """
  path = location()
  if path is None or path.is_dir():
    return path
  if os.environ.get(VARIABLE):
    try:
      found = f"is {storage.file_kind(os.stat(path).st_mode)}"
    except OSError:
      found = "does not exist"
    raise ValueError(
      f"${VARIABLE}={str(path)!r} {found}, not a zoo folder; name one, or set it to {OFF} to "
      "turn the zoo off"
    )
  return None


def chosen_folder(given: str | os.PathLike | None = None, create: bool = False) -> pathlib.Path:
  """The zoo a ``softbench zoo`` command works on: ``given`` (its ``--zoo``), else ``location()``;
  an existing folder, or with ``create`` one that can be made or written.

  Raises:
    ValueError: the zoo is turned off, or is not a folder (one line).
  """
  chosen = pathlib.Path(given) if given else location()
  if chosen is None:
    raise ValueError(f"the zoo is turned off (${VARIABLE}={OFF}); name one with --zoo DIR")
  if create:
    return storage.check_writable(chosen, "the zoo", folder=True)
  if not chosen.is_dir():
    raise ValueError(f"no zoo at {chosen}: not a folder (name one with --zoo DIR or ${VARIABLE})")
  return chosen


def file_sha256(path: pathlib.Path) -> str:
  return hashlib.sha256(path.read_bytes()).hexdigest()


def read_manifest(zoo: pathlib.Path) -> dict[str, ZooFile]:
  """The entries of ``zoo``'s manifest by path; none if it has no manifest.

  Raises:
    ValueError: the manifest is not a readable zoo manifest (one line naming it).
  """
  path = zoo / MANIFEST
  if not path.exists():
    return {}
  try:
    content = json.loads(path.read_text())
    if content.get("format") != FORMAT or content.get("version") != VERSION:
      raise ValueError(f"not a {FORMAT} manifest of version {VERSION}")
    entries = [
      ZooFile(**{**entry, "records": tuple(entry["records"])}) for entry in content["entries"]
    ]
    if any(entry.kind not in KINDS or not _inside(entry.path) for entry in entries):
      raise ValueError("an entry of unknown kind or with a path outside the zoo")
  except Exception as error:  # Any damage (bad JSON, a missing or extra field, a wrong type).
    raise ValueError(
      f"{path}: unreadable zoo manifest ({type(error).__name__}: {first_line(error)})"
    ) from None
  return {entry.path: entry for entry in entries}


def _installed_physics() -> str:
  from softbench.robots import versions  # Here: it imports MuJoCo, which reading the zoo needs not.

  return versions.current().name


def _inside(relative: str) -> bool:
  """Whether a manifest path stays inside its folder (no absolute path, no '..')."""
  parts = pathlib.PurePosixPath(relative).parts
  return bool(parts) and not pathlib.PurePosixPath(relative).is_absolute() and ".." not in parts


def write_manifest(zoo: pathlib.Path, entries: dict[str, ZooFile]) -> None:
  content = {
    "format": FORMAT,
    "version": VERSION,
    "entries": [entries[path].to_json() for path in sorted(entries)],
  }
  storage.write_atomically(zoo / MANIFEST, json.dumps(content, indent=1, sort_keys=True) + "\n")


def _say(message: str) -> None:
  print(f"softbench: zoo: {message}", file=sys.stderr, flush=True)


def restore(cache_file: pathlib.Path) -> list[str]:
  """Brings the zoo's copy of ``cache_file`` (a checkpoint or forward model under the data home)
  into the data home, if the home lacks it. Returns the zoo paths taken.

  A file whose bytes differ from the manifest's sha256 is refused with a ``ZooWarning`` (one
  line), as is an unreadable manifest; the model is then trained as if the zoo had nothing."""
  zoo = folder()
  if zoo is None or cache_file.exists():  # The common case, first: nothing to take.
    return []
  home = storage.softbench_home()
  try:
    relative = cache_file.resolve().relative_to(home.resolve()).as_posix()
  except ValueError:  # Not a cache file of the data home.
    return []
  try:
    entries = read_manifest(zoo)
  except ValueError as error:
    warnings.warn(f"{error}; training instead", ZooWarning, stacklevel=2)
    return []
  if relative in entries and _copy_checked(zoo, entries[relative], home):
    _say(f"took {relative} instead of training it (sha256 checked)")
    return [relative]
  return []


def take(cache_files: list[pathlib.Path]) -> tuple[list[str], bool]:
  """``restore`` for each cache file: the zoo paths taken, and whether every file is now in the
  data home (then none of them trains, and the babbling data behind them is not needed)."""
  taken = [path for cache_file in cache_files for path in restore(cache_file)]
  return taken, all(cache_file.is_file() for cache_file in cache_files)


def section(taken: list[str]) -> dict:
  """The record section that names the zoo files a run took (none: no section)."""
  return {"zoo": {"files": sorted(taken)}} if taken else {}


def weights(per_seed_files: list[list[pathlib.Path]]) -> list[dict[str, str]]:
  """Per seed, the sha256 of each of its files (cache files of the data home) by data-home path;
  a file the home lacks is left out."""
  home = storage.softbench_home()
  return [
    {path.relative_to(home).as_posix(): file_sha256(path) for path in files if path.is_file()}
    for files in per_seed_files
  ]


def weights_section(per_seed_files: list[list[pathlib.Path]]) -> dict:
  """The record section that names, per seed, the weight files its scores came from and their
  sha256 (``weights``), so that ``softbench zoo add`` links a record only to the weights that made
  it; none when no seed has a file."""
  hashed = [
    {"seed": seed, "files": files} for seed, files in enumerate(weights(per_seed_files)) if files
  ]
  return {"weights": {"per_seed": hashed}} if hashed else {}


def _copy_checked(zoo: pathlib.Path, entry: ZooFile, home: pathlib.Path) -> bool:
  """Copies the zoo's ``entry`` into the data home if its bytes match the manifest's sha256."""
  source = zoo / entry.path
  try:
    content = source.read_bytes()
  except OSError as error:
    warnings.warn(
      f"{source}: unreadable zoo file ({first_line(error)}); training instead",
      ZooWarning,
      stacklevel=3,
    )
    return False
  if hashlib.sha256(content).hexdigest() != entry.sha256:
    warnings.warn(
      f"{source}: its sha256 differs from the zoo manifest's (damaged or tampered); "
      f"refused, training instead",
      ZooWarning,
      stacklevel=3,
    )
    return False
  storage.write_atomically(home / entry.path, content)
  return True


def stored_config(path: pathlib.Path) -> dict:
  """The configuration a checkpoint file was saved with (``smpl.checkpoint``), or {}."""
  import torch  # pylint: disable=import-outside-toplevel  (only here: `zoo list` runs without it)

  try:
    payload = torch.load(path, map_location="cpu", weights_only=True)
    return dict(payload["config"])
  except Exception:  # A file saved without a configuration (not smpl.checkpoint's): none to list.
    return {}


def add(
  cache_files: list[tuple[pathlib.Path, str]],
  records_of: dict[pathlib.Path, list[str]],
  zoo: pathlib.Path,
  budget_bytes: int | None = BUDGET_BYTES,
) -> tuple[list[ZooFile], list[pathlib.Path]]:
  """Copies each finished ``(cache file, kind)`` of the data home into ``zoo``; ``records_of``
  names the records each file stands behind. Returns the new or changed entries, and the cache
  files skipped because the data home holds no finished file for them (an unfinished training's
  state is never taken: module docstring).

  Raises:
    ValueError: no file is finished in the data home, or the zoo would outgrow ``budget_bytes``
      (one line; nothing is changed).
  """
  home = storage.softbench_home()
  entries = read_manifest(zoo)
  planned: dict[str, tuple[bytes, ZooFile]] = {}
  skipped = []
  for cache_file, kind in cache_files:
    if not cache_file.is_file():
      skipped.append(cache_file)
      continue
    path = cache_file.relative_to(home).as_posix()
    records = tuple(
      sorted(
        set(records_of.get(cache_file, ())) | set(entries[path].records if path in entries else ())
      )
    )
    content = cache_file.read_bytes()  # Read once: hashed now, written below.
    planned[path] = (
      content,
      ZooFile(
        path,
        hashlib.sha256(content).hexdigest(),
        len(content),
        kind,
        cache_file.stem,
        stored_config(cache_file),
        records,
        _installed_physics(),
      ),
    )
  if not planned:
    raise ValueError(
      f"nothing of this setting has finished training in the data home {home}; run its "
      f"training to the end first (the zoo holds finished weights only)"
    )
  updated = {**entries, **{path: entry for path, (_, entry) in planned.items()}}
  total = size_bytes(updated)
  if budget_bytes is not None and total > budget_bytes:
    raise ValueError(
      f"the zoo would hold {total / MB:.1f} MB, over its budget of "
      f"{budget_bytes / MB:.0f} MB; nothing was added"
    )
  for path, (content, _) in planned.items():
    storage.write_atomically(zoo / path, content)
  write_manifest(zoo, updated)
  return [entry for _, entry in planned.values()], skipped


def remove(paths: set[str], zoo: pathlib.Path) -> list[ZooFile]:
  """Removes the entries at ``paths`` (relative to ``zoo``) and their files; returns the entries
  removed. The manifest is written first, so that an interruption leaves at most files it does
  not list (``check_files`` names them), never a listed file that is gone.

  Raises:
    ValueError: the zoo holds none of ``paths`` (one line; nothing is changed).
  """
  before = read_manifest(zoo)
  removed = [before[path] for path in sorted(paths) if path in before]
  if not removed:
    raise ValueError(f"the zoo {zoo} holds none of these files")
  write_manifest(zoo, {path: entry for path, entry in before.items() if path not in paths})
  for entry in removed:
    (zoo / entry.path).unlink(missing_ok=True)
    _remove_empty_parents(zoo / entry.path, zoo)
  return removed


def _remove_empty_parents(path: pathlib.Path, root: pathlib.Path) -> None:
  parent = path.parent
  while parent != root and parent.is_dir() and not any(parent.iterdir()):
    parent.rmdir()
    parent = parent.parent


def size_bytes(entries: dict[str, ZooFile]) -> int:
  return sum(entry.bytes for entry in entries.values())


def check_files(zoo: pathlib.Path) -> list[str]:
  """Problems of the zoo's files against its manifest (missing, differing sha256, unlisted), one
  line each; empty when every file is intact."""
  entries = read_manifest(zoo)
  problems = []
  for path, entry in sorted(entries.items()):
    if not (zoo / path).is_file():
      problems.append(f"{path}: missing")
    elif file_sha256(zoo / path) != entry.sha256:
      problems.append(f"{path}: sha256 differs from the manifest's")
  listed = set(entries) | {MANIFEST}
  for path in sorted(zoo.rglob("*")):
    if path.is_file() and path.relative_to(zoo).as_posix() not in listed:
      problems.append(f"{path.relative_to(zoo).as_posix()}: not in the manifest")
  return problems
