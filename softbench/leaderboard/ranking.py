"""The ranking: records grouped by robot and task, ordered by position error.

Within a group (robot, task, and for ``custom`` the trajectory; records with extra sections, such
as a fault, form groups of their own), each (agent, profile, eval mode) is represented by its
newest record (by date, then file name); older ones are kept as superseded. Rows are ordered by
the mean over seeds of the episode's module-averaged position error; an oracle (an agent that
uses the simulator itself, ``agents.is_oracle``) comes after the others and takes no place. Every
metric gets the mean and standard deviation (ddof 0, as ``softbench run`` prints) over seeds of
the per-seed means and a 95 % percentile bootstrap confidence interval of the mean
(``scipy.stats.bootstrap``, the method rliable uses by default), with a fixed random generator so
that the same records give the same numbers; with fewer than 2 seeds there is no interval.
Exp1S records are grouped apart (``exp1s_board``), in the paper's layout rather than a ranking.

Records of different physics versions (``softbench.robots.versions``) are never ranked together:
the board holds the records of the newest version any record has, and each earlier version's
records form a board of their own (``Leaderboard.earlier``), which the pages show apart.
"""

from collections.abc import Iterator
import dataclasses
import datetime
import functools
import pathlib
import re

import numpy as np

from softbench import agents
from softbench import metrics
from softbench import profiles
from softbench import records
from softbench import suite
from softbench.leaderboard import continual_board
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import selection
from softbench.records import fields as record_fields
from softbench.robots import versions

CONFIDENCE = 0.95
BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0  # Fixed: regenerating the leaderboard gives the same intervals.
MIN_SEEDS_FOR_INTERVAL = 2
RANKED_BY = "position_mm"
METRIC_LABELS = {
  "position_mm": "position (mm)",
  "orientation_deg": "orientation (deg)",
  "normalised_tip_percent": "tip error (%)",
}


@dataclasses.dataclass(frozen=True)
class Estimate:
  """A metric over seeds: mean, standard deviation and the 95 % bootstrap interval of the mean
  (``None`` with fewer than ``MIN_SEEDS_FOR_INTERVAL`` seeds)."""

  mean: float
  std: float | None  # None for a figure with no spread over seeds (an aggregate's IQM).
  interval: tuple[float, float] | None

  @classmethod
  def of(cls, values: list[float]) -> "Estimate":
    values = np.asarray(values, dtype=float)
    interval = _bootstrap_interval(tuple(values.tolist()))
    return cls(float(np.mean(values)), float(np.std(values)), interval)


# Once per process for the same per-seed values (2.3 ms of a core each): a process that boards
# the same records again (each view and aggregate the tests build) takes the interval it has.
@functools.lru_cache(maxsize=16_384)
def _bootstrap_interval(seed_values: tuple[float, ...]) -> tuple[float, float] | None:
  values = np.array(seed_values)
  if values.size < MIN_SEEDS_FOR_INTERVAL:
    return None
  if np.ptp(values) == 0:  # Every resample has the same mean; scipy would warn and give NaN.
    return float(values[0]), float(values[0])
  from scipy import stats  # Here: importing it takes 0.5 s, which softbench run need not pay.

  result = stats.bootstrap(
    (values,),
    np.mean,
    n_resamples=BOOTSTRAP_RESAMPLES,
    confidence_level=CONFIDENCE,
    method="percentile",
    vectorized=True,
    rng=np.random.default_rng(BOOTSTRAP_SEED),
  )
  return float(result.confidence_interval.low), float(result.confidence_interval.high)


COMPLETING_HELPERS = ("complete", "nearest")  # softbench.agents.completion
COMPLETED_MARK = "†"
COMPLETED_NOTE = f"{COMPLETED_MARK}: the agent completed the partial target (target completion)"


@dataclasses.dataclass(frozen=True)
class BoardEntry:
  """One record as the leaderboard shows it."""

  path: pathlib.Path
  record: dict
  estimates: dict[str, Estimate]  # By metric name, for the metrics the record holds.

  @classmethod
  def of(cls, path: pathlib.Path, record: dict) -> "BoardEntry":
    measured = [name for name in records.METRICS if name in record["per_seed"][0]]
    return cls(
      pathlib.Path(path),
      record,
      {name: Estimate.of([seed[name]["mean"] for seed in record["per_seed"]]) for name in measured},
    )

  @property
  def setting(self) -> tuple[str, str, str]:
    """What one row stands for: (agent, profile, eval mode)."""
    return self.record["agent"], self.record["profile"], self.record["eval_mode"]

  @property
  def label(self) -> str:
    return " / ".join(self.setting)

  @property
  def completion_mark(self) -> str:
    """``COMPLETED_MARK`` after a figure whose agent completed partial targets from what it
    learned (``helpers`` complete or nearest), else nothing."""
    return COMPLETED_MARK if self.record.get("helpers") in COMPLETING_HELPERS else ""

  @property
  def shown_setting(self) -> tuple[str, str, str]:
    """``setting`` as tables show it: an agent that learned by acting (a ``training`` section)
    with its environment steps and mean training wall time per seed; one that completed partial
    targets with how (``helpers``; none said: ``hold``)."""
    agent, profile, eval_mode = self.setting
    if "helpers" in self.record:
      agent += f" (helpers {self.record['helpers']})"
    spent = self.record.get("training", {}).get("per_seed", [])
    if spent and all("environment_steps" in seed for seed in spent):
      steps = {seed["environment_steps"] for seed in spent}
      seconds = float(np.mean([seed["wall_time_s"] for seed in spent]))
      took = (
        f"{seconds:.0f} s"
        if seconds < 60
        else f"{seconds / 60:.0f} min"
        if seconds < 7200
        else f"{seconds / 3600:.1f} h"
      )
      agent += f" ({'/'.join(f'{count:,}' for count in sorted(steps))} steps, {took} per seed)"
    return agent, profile, eval_mode


@dataclasses.dataclass(frozen=True)
class Group:
  """The ranked rows of one robot and task, and the records they superseded."""

  robot: str
  task: str
  variant: str  # "" for the plain task; else the trajectory and/or the extra sections.
  entries: tuple[BoardEntry, ...]  # Ranked, best first.
  superseded: tuple[BoardEntry, ...]  # Older records of a shown setting, newest first.

  @property
  def title(self) -> str:
    return f"{self.robot} · {self.task}" + (f" ({self.variant})" if self.variant else "")

  @property
  def anchor(self) -> str:
    """An id for links: letters, digits and dashes."""
    return re.sub(r"[^a-z0-9]+", "-", self.title.lower()).strip("-")

  @property
  def metrics(self) -> tuple[str, ...]:
    """The metrics any row holds, in ``records.METRICS`` order."""
    return tuple(
      name for name in records.METRICS if any(name in entry.estimates for entry in self.entries)
    )


@dataclasses.dataclass(frozen=True)
class Leaderboard:
  groups: tuple[Group, ...]  # Of softbench run records.
  record_count: int  # Of every kind, of this board's physics version.
  latest_date: str | None  # The newest record's date: the pages carry no time of their own.
  exp1s: tuple[exp1s_board.Group, ...] = ()  # Of softbench run --protocol exp1s records.
  physics: str = versions.LATEST  # The physics version of every record on the board.
  earlier: tuple["Leaderboard", ...] = ()  # The records of earlier physics versions, oldest first.
  verified: frozenset[str] = frozenset()  # File names of the records the zoo re-scored (verified).
  continual: tuple[continual_board.Group, ...] = ()  # Of softbench run --protocol continual.

  def is_verified(self, entry: "BoardEntry") -> bool:
    """Whether ``entry``'s record is in the verification ledger as it is now
    (``softbench.leaderboard.verified``)."""
    return entry.path.name in self.verified

  @property
  def physics_description(self) -> str:
    return f"physics {self.physics} ({versions.VERSIONS[self.physics].description})"

  def of_physics(self, name: str) -> "Leaderboard":
    """The board of physics version ``name``: this one or an earlier one (empty if no record
    has that version)."""
    for board in (self, *self.earlier):
      if board.physics == name:
        return board
    versions.VERSIONS[name]  # KeyError for an unknown name.
    return Leaderboard((), 0, None, physics=name)


def _group_key(record: dict) -> tuple[str, str, str]:
  variant = [f"trajectory {record['trajectory']}"] if record["trajectory"] is not None else []
  variant += [f"fault {fault['text']}" for fault in record.get("faults") or []]
  variant += [f"with {name}" for name in records.sections(record)]
  return record["robot"], record["task"], ", ".join(variant)


def robot_order(robot: str) -> tuple:
  """Robots by family, then module count (tendon-2 before tendon-10, tendon-5 before
  tendon-local-1)."""
  family, _, size = robot.rpartition("-")
  return family, int(size) if size.isdigit() else 0, robot


def known_first(name: str, known) -> tuple:
  """Sort key: the ``known`` names in their order, then any others by name."""
  known = list(known)
  return (0, known.index(name), "") if name in known else (1, 0, name)


def setting_order(robot: str, profile: str, eval_mode: str) -> tuple:
  """Sort key of a robot, profile and eval mode: robots by ``robot_order``, profiles in
  ``profiles.PROFILES`` order (paper first), eval modes as ``ERROR_SOURCES`` lists them."""
  return (
    robot_order(robot),
    known_first(profile, profiles.PROFILES),
    known_first(eval_mode, record_fields.ERROR_SOURCES),
  )


def plain_entries(board: "Leaderboard") -> Iterator[tuple[Group, BoardEntry]]:
  """Every shown row of a plain task (no trajectory or extra section), with its group."""
  for group in board.groups:
    if not group.variant:
      for entry in group.entries:
        yield group, entry


def _moment(record: dict) -> datetime.datetime:
  return datetime.datetime.fromisoformat(record["date"])  # Checked, with a time zone.


def rank(
  loaded: list[tuple[pathlib.Path, dict]], verified: frozenset[str] = frozenset()
) -> Leaderboard:
  """The leaderboard of checked records (``records.read_folder``) of every kind: the records of
  the newest physics version among them (the installed one if there are none), with a board of
  its own for each earlier version's; ``verified``: the file names of the records the zoo's
  weights re-scored (``softbench.leaderboard.verified``)."""
  by_physics: dict[str, list] = {}
  for path, record in loaded:
    by_physics.setdefault(record_fields.physics_of(record), []).append((path, record))
  order = list(versions.VERSIONS)
  newest = max(by_physics, key=order.index, default=versions.current().name)
  earlier = tuple(
    dataclasses.replace(_rank_one(by_physics[name], name), verified=verified)
    for name in order
    if name in by_physics and name != newest
  )
  newest_board = _rank_one(by_physics.get(newest, []), newest)
  return dataclasses.replace(newest_board, earlier=earlier, verified=verified)


def _rank_one(loaded: list[tuple[pathlib.Path, dict]], physics: str) -> Leaderboard:
  """The leaderboard of checked records of one physics version."""
  by_group: dict[tuple[str, str, str], list[BoardEntry]] = {}
  for path, record in loaded:
    # Adaptive activation records hold per-target results, no per-seed ones
    # (softbench.runners.adaptive).
    if record["format"] == records.FORMAT and record["per_seed"]:
      by_group.setdefault(_group_key(record), []).append(BoardEntry.of(path, record))
  groups = []
  for key in sorted(by_group, key=lambda k: (robot_order(k[0]), suite.TASKS.index(k[1]), k[2])):
    shown, superseded = selection.newest_per_setting(by_group[key])
    ranked = sorted(
      shown,
      key=lambda entry: (
        agents.is_oracle(entry.setting[0]),
        entry.estimates[RANKED_BY].mean,
        entry.setting,
      ),
    )
    groups.append(Group(*key, tuple(ranked), tuple(superseded)))
  latest = max((record for _, record in loaded), key=_moment, default=None)
  return Leaderboard(
    tuple(groups),
    len(loaded),
    None if latest is None else latest["date"],
    exp1s_board.group(loaded),
    physics,
    continual=continual_board.group(loaded),
  )


ORACLE_PLACE = "oracle"  # The place column of an oracle's row (agents.is_oracle): not ranked.


def places(entries: tuple[BoardEntry, ...]) -> list[str]:
  """The place of each of a group's ranked ``entries``: 1, 2, ... and ``ORACLE_PLACE`` for an
  oracle, which ranks after every other agent and takes no place."""
  shown, place = [], 0
  for entry in entries:
    if agents.is_oracle(entry.setting[0]):
      shown.append(ORACLE_PLACE)
    else:
      place += 1
      shown.append(str(place))
  return shown


decimals_of = metrics.decimals_of
number = metrics.number


def mean_and_std(estimate: Estimate) -> str:
  """``mean ± std``, both with the decimals of the mean; the mean alone where there is no
  standard deviation."""
  if estimate.std is None:
    return number(estimate.mean)
  return metrics.mean_and_std(estimate.mean, estimate.std)


def cell(estimate: Estimate | None) -> str:
  """``mean ± std [low, high]``, all with the decimals of the mean; ``-`` for a metric the
  record does not hold."""
  if estimate is None:
    return "-"
  text = mean_and_std(estimate)
  return text if estimate.interval is None else f"{text} {interval_text(estimate)}"


def interval_text(estimate: Estimate) -> str:
  """``[low, high]`` of the bootstrap interval, with the decimals of the mean."""
  decimals = decimals_of(estimate.mean)
  low, high = estimate.interval
  return f"[{number(low, decimals)}, {number(high, decimals)}]"
