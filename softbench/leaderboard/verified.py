"""Which records the zoo's weights re-score: the verification ledger beside a results folder.

A record's ``sha256`` (``softbench.records``) says the file is whole and unedited since it was
sealed; anyone can recompute it, so it cannot say that softbench made the figures. What can be
checked is whether the weights behind a record score it again: ``softbench zoo verify``
re-scores, in an empty data home, every seed of every record the zoo stands behind and writes the
records whose seeds all agree (``agrees``: within ``RELATIVE_TOLERANCE``, since another kind of
CPU changes the last digits) into the ledger ``verified.json`` beside the results folder
(``leaderboard/verified.json`` for the committed records): per record, the sha256 it had, the
seeds re-scored, the largest relative difference and the machine that re-scored it. The pages
mark a record **verified** only while its sha256 is the ledger's (a record edited and resealed
afterwards, or one that no weights stand behind, is unverified), so a forged record is shown as
such, and anyone can check a ledger entry by running ``softbench zoo verify`` again.
"""

import dataclasses
import json
import math
import pathlib

from softbench import storage

FILE_NAME = "verified.json"
FORMAT = "softbench-verified"
VERSION = 1
RELATIVE_TOLERANCE = 1e-3
"""How far a re-scored figure may be from the record's, relative. Across kinds of CPU the same
weights re-score a tracking record from the 8th significant digit on (1.4e-8 to 2.7e-7 mm of
6.69 mm on tendon-3's spiral, AMD EPYC against Intel Xeon: docs/physics-versions.md), and a
``babbling`` one, whose jumping targets carry a last-bit difference furthest, by up to 4.5e-5
(4.280426 against 4.280235 mm: docs/leaderboard.md); 1e-3 leaves a margin of 20 over that and
still moves no figure by more than one unit of the last digit the pages show."""
ABSOLUTE_TOLERANCE = 1e-9  # For figures near zero (a mean reward of 0).


def path_for(results: pathlib.Path) -> pathlib.Path:
  """The ledger of the records in ``results``: ``verified.json`` beside the folder."""
  return pathlib.Path(results).parent / FILE_NAME


def agrees(new, old) -> tuple[bool, float]:
  """Whether a re-scored value (a seed's entry) agrees with the record's: the same structure,
  equal text and integers, floats within the tolerances; and the largest relative difference."""
  if isinstance(old, dict):
    if not isinstance(new, dict) or new.keys() != old.keys():
      return False, math.inf
    parts = [agrees(new[key], old[key]) for key in old]
  elif isinstance(old, list):
    if not isinstance(new, list) or len(new) != len(old):
      return False, math.inf
    parts = [agrees(a, b) for a, b in zip(new, old)]
  elif isinstance(old, float) and isinstance(new, (int, float)) and not isinstance(new, bool):
    difference = abs(new - old) / max(abs(old), ABSOLUTE_TOLERANCE)
    close = math.isclose(new, old, rel_tol=RELATIVE_TOLERANCE, abs_tol=ABSOLUTE_TOLERANCE)
    return close, difference
  else:
    return new == old and type(new) is type(old), 0.0 if new == old else math.inf
  return all(ok for ok, _ in parts), max((difference for _, difference in parts), default=0.0)


def read(results: pathlib.Path) -> dict[str, dict]:
  """The ledger's entries by record file name; none where there is no ledger.

  Raises:
    ValueError: the ledger is not one (one line naming it).
  """
  path = path_for(results)
  if not path.exists():
    return {}
  try:
    ledger = json.loads(path.read_text(encoding="utf-8"))
  except (OSError, ValueError) as error:
    raise ValueError(f"{path}: not a verification ledger ({storage.first_line(error)})") from None
  if not (isinstance(ledger, dict) and ledger.get("format") == FORMAT):
    raise ValueError(f"{path}: not a verification ledger (format {FORMAT} expected)")
  entries = ledger.get("records")
  if not isinstance(entries, dict) or not all(isinstance(e, dict) for e in entries.values()):
    raise ValueError(f"{path}: its records are not a mapping of entries")
  return entries


def verified(results: pathlib.Path, loaded: list[tuple[pathlib.Path, dict]]) -> frozenset[str]:
  """The file names of the ``loaded`` records that the ledger holds as they are now: the same
  sha256, every seed re-scored."""
  entries = read(results)
  found = set()
  for path, record in loaded:
    entry = entries.get(path.name, {})
    seeds = {seed["seed"] for seed in record.get("per_seed", [])}
    if entry.get("sha256") == record["sha256"] and seeds and seeds <= set(entry.get("seeds", [])):
      found.add(path.name)
  return frozenset(found)


def write(results: pathlib.Path, outcomes: dict[str, "Outcome"]) -> pathlib.Path:
  """Updates the ledger (atomically) with ``outcomes`` (record file name -> what re-scoring it
  found): a record whose every seed agreed is entered, one with a seed that did not is dropped,
  one only partly re-scored (``zoo verify --quick``) stays as it was; returns the ledger's path."""
  entries = dict(read(results))
  for name, outcome in sorted(outcomes.items()):
    every_seed = {seed["seed"] for seed in outcome.record.get("per_seed", [])}
    if outcome.disagreed:
      entries.pop(name, None)
    elif every_seed and every_seed <= set(outcome.seeds):
      entries[name] = {
        "sha256": outcome.record["sha256"],
        "seeds": sorted(outcome.seeds),
        "largest_relative_difference": outcome.difference,
        "date": outcome.date,
        "machine": outcome.machine,
      }
  path = path_for(results)
  ledger = {"format": FORMAT, "version": VERSION, "records": dict(sorted(entries.items()))}
  storage.write_atomically(path, json.dumps(ledger, indent=1) + "\n")
  return path


@dataclasses.dataclass
class Outcome:
  """What re-scoring one record found: the seeds that agreed, whether any did not, the largest
  relative difference, and when and where it was re-scored."""

  record: dict
  date: str
  machine: dict
  seeds: list[int] = dataclasses.field(default_factory=list)
  disagreed: bool = False
  difference: float = 0.0
