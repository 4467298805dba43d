"""``softbench zoo verify``: re-scores committed records from the zoo's weights alone, in an
empty data home, and compares every figure with the record's within ``verified.RELATIVE_TOLERANCE``
(``verify``; ``verify_zoo`` checks the zoo first and prints what it finds); the records whose
every seed agrees go into the verification ledger that the pages mark records by
(``softbench.leaderboard.verified``)."""

from collections.abc import Iterator
import contextlib
import dataclasses
import json
import os
import pathlib
import tempfile
import time

from softbench import agents as agent_registry
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import storage
from softbench import zoo
from softbench.leaderboard import verified
from softbench.learning import exp1s as exp1s_training
from softbench.records import fields as record_fields
from softbench.records import provenance
from softbench.robots import versions
from softbench.runners import continual
from softbench.runners import run as run_module
from softbench.runners import run_settings
from softbench.suite import references as suite_references


@dataclasses.dataclass(frozen=True)
class Check:
  """One seed of one record, re-scored from the zoo."""

  record: str
  seed: int
  agrees: bool  # Every figure within verified.RELATIVE_TOLERANCE of the record's.
  detail: str  # What differs, or how the record could not be re-scored; '' when it agrees.
  seconds: float
  difference: float = 0.0  # The largest relative difference of a figure.

  def describe(self) -> str:
    """One line: ``RECORD seed N: identical (12.3 s)``, ``agrees (largest relative difference
    2.1e-08; 12.3 s)``, or ``DIFFERS: ...`` and what differs."""
    if not self.agrees:
      verdict = f"DIFFERS: {self.detail} ({self.seconds:.1f} s)"
    elif self.difference == 0:
      verdict = f"identical ({self.seconds:.1f} s)"
    else:
      verdict = f"agrees (largest relative difference {self.difference:.1e}; {self.seconds:.1f} s)"
    return f"{self.record} seed {self.seed}: {verdict}"


REFERENCES_FOLDER = suite_references.FOLDER  # In a data home.


class ZooMismatch(RuntimeError):
  """``softbench zoo verify`` found a record that the zoo's weights do not reproduce."""


@contextlib.contextmanager
def empty_data_home(references: pathlib.Path | None = None) -> Iterator[pathlib.Path]:
  """Within the block the data home is a new empty folder, so that nothing trained or collected
  before is reused; ``references``: a folder of reference trajectories simulated during this
  verification, shared by its checks (simulated from the physics alone, no weights; tendon-3's
  take about 30 s each)."""
  previous = os.environ.get(storage.HOME_VARIABLE)
  with tempfile.TemporaryDirectory(prefix="softbench-zoo-verify-") as home:
    if references is not None:
      (pathlib.Path(home) / REFERENCES_FOLDER).symlink_to(references, target_is_directory=True)
    os.environ[storage.HOME_VARIABLE] = home
    try:
      yield pathlib.Path(home)
    finally:
      if previous is None:
        os.environ.pop(storage.HOME_VARIABLE, None)
      else:
        os.environ[storage.HOME_VARIABLE] = previous


def agent_of(entry: zoo.ZooFile) -> str:
  """The agent whose weights ``entry`` holds (an Exp1S network is smpl's)."""
  return entry.config.get("agent", "smpl")


def planned(
  zoo_folder: pathlib.Path, agents: tuple[str, ...] | None, quick: bool
) -> list[tuple[str, int]]:
  """(record name, seed) pairs to re-score: every record each agent checkpoint of the zoo stands
  behind, for the agents named (all if None); ``quick``: seed 0 only, one record each."""
  pairs = []
  for entry in zoo.read_manifest(zoo_folder).values():
    if entry.kind != "agent" or (agents and agent_of(entry) not in agents):
      continue
    seed = entry.config.get("seed")
    if quick and seed != 0:
      continue
    names = sorted(entry.records)
    pairs += [(name, seed) for name in (names[:1] if quick else names)]
  return sorted(set(pairs))


def rescored(record: dict, seed: int) -> dict:
  """Seed ``seed``'s entry of ``record`` computed again (in the current data home)."""
  profile = profiles.get(record["profile"])
  if record["format"] == continual.RECORD_FORMAT:
    family = next(
      name
      for name in robots.TENDON_FAMILY_NAMES
      if exp1s_training.protocol(name).robot_names == tuple(record["robots"])
    )
    # Kept episodes name their place in the data home (``episodes.snapshots``): keep them there.
    home = storage.softbench_home()
    home.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rescored-episodes-", dir=home) as kept:
      entry = continual.score_seed(seed, profile, False, pathlib.Path(kept), family)
  else:
    module = record["scored_modules"][0] if record["task"] == "reach" else None
    settings = run_settings.settings(
      record["task"],
      record["agent"],
      record["robot"],
      1,
      record["profile"],
      record["eval_mode"],
      record["trajectory"],
      module,
    )
    entry = run_module.score_seed(settings, seed)
  return json.loads(json.dumps(entry))  # As a record stores it.


def _difference(new: dict, old: dict) -> str:
  """Where two seed entries first differ, in one line."""
  for metric in records.METRICS:
    if metric in old and new.get(metric, {}).get("mean") != old[metric]["mean"]:
      return f"{metric} mean {new.get(metric, {}).get('mean')!r} against {old[metric]['mean']!r}"
  keys = sorted(key for key in old.keys() | new.keys() if new.get(key) != old.get(key))
  return f"differs in {', '.join(keys)}"


def verify(
  results: pathlib.Path,
  zoo_folder: pathlib.Path,
  agents: tuple[str, ...] | None = None,
  quick: bool = False,
  report=None,
) -> list[Check]:
  """Re-scores ``planned`` records of the installed physics version in an empty data home, one
  seed at a time, and compares each seed's figures with the record's; ``report(check)`` sees
  each check as it ends. Records of another physics version are left out (``other_physics``).
  After each check the ledger (``verified.write``) holds what is known, so an interrupted
  verification keeps what it found."""
  found = {path.name: record for path, record in records.read_folder(results)}
  machine = provenance.provenance("cpu")
  outcomes: dict[str, verified.Outcome] = {}
  checks = []
  with tempfile.TemporaryDirectory(prefix="softbench-zoo-verify-references-") as shared:
    shared_references = pathlib.Path(shared)
    for name, seed in planned(zoo_folder, agents, quick):
      if name in other_physics(found):
        continue
      started = time.perf_counter()
      record = found.get(name)
      stored = (
        None
        if record is None
        else next((entry for entry in record["per_seed"] if entry["seed"] == seed), None)
      )
      if stored is None:
        check = Check(name, seed, False, "no such record or seed in " + str(results), 0.0)
      else:
        with empty_data_home(shared_references):
          new = rescored(record, seed)
        agreed, difference = verified.agrees(new, stored)
        check = Check(
          name,
          seed,
          agreed,
          "" if agreed else _difference(new, stored),
          time.perf_counter() - started,
          difference if agreed else 0.0,
        )
        outcome = outcomes.setdefault(
          name, verified.Outcome(record, machine["date"], machine["machine"])
        )
        if agreed:
          outcome.seeds.append(seed)
          outcome.difference = max(outcome.difference, difference)
        outcome.disagreed |= not agreed
        verified.write(results, outcomes)
      checks.append(check)
      if report is not None:
        report(check)
  return checks


def other_physics(found: dict[str, dict]) -> set[str]:
  """The names of the records in ``found`` made with another physics version than the
  installed one: this MuJoCo cannot re-score them."""
  here = versions.current().name
  return {name for name, record in found.items() if record_fields.physics_of(record) != here}


def verify_zoo(
  results: pathlib.Path,
  zoo_folder: pathlib.Path,
  agents: tuple[str, ...] | None = None,
  quick: bool = False,
) -> list[Check]:
  """``softbench zoo verify``: checks the agents' names and the zoo's files, then ``verify``s,
  printing each check as it ends and then the tally.

  Raises:
    ValueError: an unknown agent, or a zoo file missing, damaged or unlisted (one line, before
      anything is re-scored).
    ZooMismatch: a re-scored seed differs from its record.
  """
  for name in agents or ():
    agent_registry.describe(name)
  problems = zoo.check_files(zoo_folder)
  if problems:
    raise ValueError(
      f"{zoo_folder}: {problems[0]} ({len(problems)} problems; see softbench zoo list)"
    )
  found = {path.name: record for path, record in records.read_folder(results)}
  wanted = planned(zoo_folder, agents, quick)
  elsewhere = sorted({name for name, _ in wanted if name in other_physics(found)})
  if elsewhere:
    kinds = sorted({record_fields.physics_of(found[name]) for name in elsewhere})
    where = "; ".join(f"{kind}: {versions.VERSIONS[kind].install}" for kind in kinds)
    note = (
      f"{len(elsewhere)} records of physics {', '.join(kinds)} cannot be re-scored on "
      f"physics {versions.current().name} (MuJoCo {versions.engine_version()}); "
      f"verify them where their stack is installed ({where})"
    )
    if len(elsewhere) == len({name for name, _ in wanted}):
      raise ValueError(note)
    print(f"skipped: {note}", flush=True)
  checks = verify(
    results, zoo_folder, agents, quick, lambda check: print(check.describe(), flush=True)
  )
  differing = sum(not check.agrees for check in checks)
  print(
    f"{len(checks) - differing} of {len(checks)} re-scored seeds agree with their records "
    f"(every figure within {verified.RELATIVE_TOLERANCE:g} relative); verified records: "
    f"{verified.path_for(results)}"
  )
  if differing:
    raise ZooMismatch(f"{differing} re-scored seeds differ from their records")
  return checks
