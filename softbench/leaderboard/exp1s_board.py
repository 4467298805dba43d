"""Exp1S records on the leaderboard, in the paper's layout, with the paper's values beside ours.

Records are grouped by their sequence of configurations (``robots``; records with extra sections
form groups of their own); in a group, each (agent, profile) is represented by its newest record
(by date, then file name), and older ones are kept as superseded. Each shown record gives:

- per loop (closed, open), configurations by rows, per task the end effector's position (mm) and
  orientation (deg) error, mean ± std over seeds (ddof 0, as ``softbench run`` prints), each row
  followed by the paper's row for the same configuration (``paper_exp1s.json``);
- the normalised tip error (%) per task and loop, mean ± std over seeds;
- the forgetting matrix: normalised tip error (%) on the forgetting task, closed loop, of each
  configuration (columns) after each training stage (rows), mean over seeds.

Every page (``text``, ``markdown_page``, ``html_page``) renders the same ``Table`` objects.
"""

import dataclasses
import pathlib
import re

from softbench import metrics
from softbench import records
from softbench.leaderboard import paper_tables
from softbench.leaderboard import selection
from softbench.leaderboard.figure_table import Table
from softbench.records import exp1s as exp1s_records

PAPER_FILE = "paper_exp1s.json"  # In this package; its "source" names the paper's table.
PAPER_METRICS = {"position_mm": "pos (mm)", "orientation_deg": "ori (deg)"}
SOURCES = ("softbench", "paper")  # The two rows of each configuration.
LOOP_LABELS = {
  "closed": "closed loop (softbench: error measured in physics)",
  "open": "open loop (no error fed back)",
}


def paper() -> dict:
  """The paper's Exp1S table (``paper_exp1s.json``): source, note, robots and
  ``scores[loop][task][metric]``, one [mean, std] per configuration."""
  return paper_tables.load(PAPER_FILE)


def figure(mean: float, std: float) -> str:
  """``mean ± std`` with 2 decimals, as the paper prints its table."""
  return f"{mean:.2f} ± {std:.2f}"


def _figure(statistic: metrics.Statistic) -> str:
  return figure(statistic.mean, statistic.std)


@dataclasses.dataclass(frozen=True)
class Exp1sEntry:
  """One checked Exp1S record as the leaderboard shows it."""

  path: pathlib.Path
  record: dict

  @property
  def setting(self) -> tuple[str, str]:
    """What one entry stands for: (agent, profile)."""
    return self.record["agent"], self.record["profile"]

  @property
  def label(self) -> str:
    return " / ".join(self.setting)

  def statistic(self, loop: str, task: str, configuration: int, metric: str) -> metrics.Statistic:
    """Mean and std over seeds of one configuration's (0-based) error."""
    return metrics.Statistic.of(
      [seed["scores"][loop][task][configuration][metric] for seed in self.record["per_seed"]]
    )

  def forgetting(self) -> list[list[float | None]]:
    """The forgetting matrix (stages x configurations, normalised tip %), mean over seeds;
    ``None`` above the diagonal."""
    size = len(self.record["robots"])
    return [
      [
        metrics.Statistic.of(
          [seed["forgetting_tip_percent"][stage][column] for seed in self.record["per_seed"]]
        ).mean
        if column <= stage
        else None
        for column in range(size)
      ]
      for stage in range(size)
    ]


@dataclasses.dataclass(frozen=True)
class Group:
  """The shown entries of one sequence of configurations, and the records they superseded."""

  robots: tuple[str, ...]
  variant: str  # "" for a plain record; else its extra sections.
  entries: tuple[Exp1sEntry, ...]  # Newest per (agent, profile), by agent then profile.
  superseded: tuple[Exp1sEntry, ...]  # Older records of a shown setting, newest first.

  @property
  def title(self) -> str:
    return f"Exp1S · {', '.join(self.robots)}" + (f" ({self.variant})" if self.variant else "")

  @property
  def anchor(self) -> str:
    """An id for links: letters, digits and dashes."""
    return re.sub(r"[^a-z0-9]+", "-", self.title.lower()).strip("-")


def group(loaded: list[tuple[pathlib.Path, dict]]) -> tuple[Group, ...]:
  """The Exp1S groups of checked records (``records.read_folder``); other formats are ignored."""
  by_group: dict[tuple[tuple[str, ...], str], list[Exp1sEntry]] = {}
  for path, record in loaded:
    if record["format"] == exp1s_records.FORMAT:
      key = tuple(record["robots"]), ", ".join(f"with {name}" for name in records.sections(record))
      by_group.setdefault(key, []).append(Exp1sEntry(pathlib.Path(path), record))
  groups = []
  for key in sorted(by_group, key=lambda k: (len(k[0]), k)):
    newest, superseded = selection.newest_per_setting(by_group[key])
    shown = sorted(newest, key=lambda entry: entry.setting)
    groups.append(Group(*key, tuple(shown), tuple(superseded)))
  return tuple(groups)


def _paper_cells(robot: str, loop: str, task: str) -> list[str]:
  table, robot = paper(), paper_tables.paper_robot(robot)
  if robot not in table["robots"] or task not in table["scores"][loop]:
    return ["-"] * len(PAPER_METRICS)
  index = table["robots"].index(robot)
  return [figure(*table["scores"][loop][task][metric][index]) for metric in PAPER_METRICS]


def loop_table(entry: Exp1sEntry, loop: str) -> Table:
  """The paper's Exp1S layout for one loop: per configuration our row, then the paper's."""
  tasks = entry.record["tasks"]
  header = (
    "config",
    "robot",
    "source",
    *(f"{task} {label}" for task in tasks for label in PAPER_METRICS.values()),
  )
  rows = []
  for index, robot in enumerate(entry.record["robots"]):
    ours = [
      _figure(entry.statistic(loop, task, index, metric))
      for task in tasks
      for metric in PAPER_METRICS
    ]
    theirs = [cell for task in tasks for cell in _paper_cells(robot, loop, task)]
    rows += [(str(index + 1), robot, SOURCES[0], *ours), ("", "", SOURCES[1], *theirs)]
  return Table(
    f"{LOOP_LABELS[loop]}: end-effector position (mm) and orientation (deg) error, "
    f"mean ± std over seeds",
    header,
    tuple(rows),
    label_columns=3,
    paper_rows=tuple(range(1, len(rows), len(SOURCES))),
  )


def tip_table(entry: Exp1sEntry) -> Table:
  """Normalised tip error (%) per configuration, task and loop, mean ± std over seeds."""
  tasks = entry.record["tasks"]
  header = (
    "config",
    "robot",
    *(f"{task} {loop}" for task in tasks for loop in exp1s_records.LOOPS),
  )
  rows = tuple(
    (
      str(index + 1),
      robot,
      *(
        _figure(entry.statistic(loop, task, index, "normalised_tip_percent"))
        for task in tasks
        for loop in exp1s_records.LOOPS
      ),
    )
    for index, robot in enumerate(entry.record["robots"])
  )
  return Table(
    "normalised tip error (%): position error / robot length, mean ± std over seeds "
    "(the paper gives no numbers for it)",
    header,
    rows,
    label_columns=2,
  )


def forgetting_table(entry: Exp1sEntry) -> Table:
  """The forgetting matrix as text: rows after each stage, columns per configuration."""
  robots = entry.record["robots"]
  rows = tuple(
    (f"{stage + 1}: {robots[stage]}", *("" if value is None else f"{value:.2f}" for value in row))
    for stage, row in enumerate(entry.forgetting())
  )
  return Table(
    f"forgetting matrix: normalised tip error (%) on {exp1s_records.FORGETTING_TASK}, "
    f"closed loop, of each configuration (columns) after each training stage (rows), "
    f"mean over seeds (the paper shows it only as a figure)",
    ("after stage", *robots),
    rows,
    label_columns=1,
  )


def score_tables(entry: Exp1sEntry) -> tuple[Table, ...]:
  """The error tables of one entry: per loop, then the normalised tip error."""
  return (*(loop_table(entry, loop) for loop in exp1s_records.LOOPS), tip_table(entry))


def tables(entry: Exp1sEntry) -> tuple[Table, ...]:
  """Every table of one entry, in page order: the error tables, then the forgetting matrix."""
  return (*score_tables(entry), forgetting_table(entry))


def describe(entry: Exp1sEntry) -> str:
  """One line on what the entry is: agent, profile, seeds and date."""
  return (
    f"{entry.label}, {entry.record['seeds']} seed(s), {entry.record['date']}, end "
    f"effector in physics"
  )


def explanation() -> str:
  """How to read the Exp1S sections, for each page's introduction."""
  return (
    "Exp1S records (softbench run --protocol exp1s: SMPL learns tendon-1 .. tendon-5 in "
    "sequence) have sections of their own in the paper's layout: per loop, configurations "
    "by rows, per task the end effector's position (mm) and orientation (deg) error, mean "
    "± std over seeds, each row followed by the paper's; the normalised tip error (%); and "
    "the forgetting matrix (normalised tip error after each training stage, mean over "
    "seeds). The newest record per agent and profile is shown."
  )


def about_paper() -> str:
  """What the paper rows are and how they differ from ours, for each page's Exp1S section."""
  return f"Paper rows: {paper()['source']} {paper()['note']}"
