"""Continual records on the leaderboard: a table per stream, family and profile, a row per
strategy (its newest record; older ones superseded), and each strategy's error matrix.

A row gives, mean ± std over seeds (ddof 0) with the 95 % bootstrap interval over seeds as the
ranking gives it (``ranking.Estimate``): the average final error (mm, and % of length), forgetting
(mm), forward transfer against the table's ``independent`` record (% of its error removed, on the
seeds both hold; ``softbench.continual.metrics``), the same on the training curves, the
parameters after the last stage and the training time over all stages. Rows are ordered by average
final error. A second table gives each configuration's error right after its own stage, per
strategy, and the forward transfer on it. Every page (``text``, ``markdown_page``,
``html_page``) renders the same ``Table`` objects.
"""

import dataclasses
import pathlib
import re

import numpy as np

from softbench.continual import metrics as continual_metrics
from softbench.leaderboard import ranking
from softbench.leaderboard import selection
from softbench.leaderboard.figure_table import Table
from softbench.records import continual as continual_records

REFERENCE = "independent"  # Forward transfer is measured against its record.
PERCENT = 100.0


@dataclasses.dataclass(frozen=True)
class ContinualEntry:
  """One checked continual record as the leaderboard shows it."""

  path: pathlib.Path
  record: dict

  @property
  def setting(self) -> tuple[str]:
    return (self.record["agent"],)

  @property
  def label(self) -> str:
    return self.record["agent"]

  def estimate(self, figure, unit: str = "mm") -> "ranking.Estimate":
    """``figure`` of the seeds' error matrices in ``unit``: mean, std and bootstrap interval."""
    return ranking.Estimate.of(self.per_seed(figure, unit))

  def per_seed(self, figure, unit: str = "mm") -> list[float]:
    """``figure`` (a function of one seed's error matrix) of every seed."""
    return [figure(matrix) for matrix in continual_metrics.matrices(self.record, unit)]

  def mean_matrix(self, unit: str = "%") -> np.ndarray:
    """The error matrix (stages x configurations), mean over seeds; NaN above the diagonal."""
    return np.mean(continual_metrics.matrices(self.record, unit), axis=0)


@dataclasses.dataclass(frozen=True)
class Group:
  """The shown entries of one stream, family and profile, and the records they superseded."""

  stream: str
  family: str
  profile: str
  entries: tuple[ContinualEntry, ...]  # Newest per strategy, by average final error.
  superseded: tuple[ContinualEntry, ...]

  @property
  def title(self) -> str:
    return f"Continual · {self.stream} ({self.family}), profile {self.profile}"

  @property
  def anchor(self) -> str:
    return re.sub(r"[^a-z0-9]+", "-", self.title.lower()).strip("-")

  @property
  def labels(self) -> list[str]:
    return [c["label"] for c in self.entries[0].record["configurations"]]

  @property
  def reference(self) -> ContinualEntry | None:
    return next((entry for entry in self.entries if entry.label == REFERENCE), None)


def group(loaded: list[tuple[pathlib.Path, dict]]) -> tuple[Group, ...]:
  """The continual groups of checked records (``records.read_folder``); others are ignored."""
  by_group: dict[tuple[str, str, str], list[ContinualEntry]] = {}
  for path, record in loaded:
    if record["format"] == continual_records.FORMAT:
      key = record["stream"], record["family"], record["profile"]
      by_group.setdefault(key, []).append(ContinualEntry(pathlib.Path(path), record))
  groups = []
  for key in sorted(by_group):
    newest, superseded = selection.newest_per_setting(by_group[key])
    ordered = sorted(
      newest,
      key=lambda entry: (np.mean(entry.per_seed(continual_metrics.average_final)), entry.label),
    )
    groups.append(Group(*key, tuple(ordered), tuple(superseded)))
  return tuple(groups)


def _transfer(
  entry: ContinualEntry, reference: ContinualEntry | None, name: str
) -> "ranking.Estimate | None":
  """Forward transfer ``name`` of ``entry`` against ``reference`` in %, over the seeds both
  hold; None without a reference (or for the reference itself)."""
  if reference is None or entry is reference:
    return None
  values = continual_metrics.transfer(entry.record, reference.record)[name]
  return ranking.Estimate.of([value * PERCENT for value in values]) if values else None


def table(group: Group, with_times: bool = True) -> Table:
  """The strategies of ``group`` side by side (module docstring); without the training times
  unless ``with_times`` (they change from machine to machine; the docs' tables leave them out)."""
  rows = []
  for entry in group.entries:
    last = [seed["stages"] for seed in entry.record["per_seed"]]
    rows.append(
      (
        entry.label,
        str(entry.record["seeds"]),
        ranking.cell(entry.estimate(continual_metrics.average_final)),
        ranking.cell(entry.estimate(continual_metrics.average_final, "%")),
        ranking.cell(entry.estimate(continual_metrics.forgetting)),
        ranking.cell(_transfer(entry, group.reference, "forward_transfer")),
        ranking.cell(_transfer(entry, group.reference, "curve_transfer")),
        f"{last[0][-1]['parameters']:,}",
        f"{np.mean([sum(s['training_seconds'] for s in stages) for stages in last]):.0f}",
      )
    )
  header = (
    "strategy",
    "seeds",
    "final error (mm)",
    "final error (%)",
    "forgetting (mm)",
    "forward transfer (%)",
    "curve transfer (%)",
    "parameters",
    "training (s)",
  )
  kept = len(header) if with_times else len(header) - 1
  return Table(
    f"{group.stream} ({group.family}, {group.profile} profile): {', '.join(group.labels)}; "
    f"end-effector error on "
    f"{group.entries[0].record['task']} in physics after the last stage, mean ± std over seeds "
    f"[95% bootstrap CI]; forward transfer against {REFERENCE} (share of its error removed on "
    f"each newly learned configuration; on training curves: 1 - loss AUC ratio)",
    header[:kept],
    tuple(row[:kept] for row in rows),
    label_columns=1,
  )


def diagonal_table(group: Group) -> Table:
  """Each configuration's error right after its own stage (the matrix's diagonal, mm, mean ± std
  over seeds) per strategy, then each strategy's forward transfer on it against ``REFERENCE``
  (%, over the seeds both hold; from the second configuration on)."""
  reference = group.reference
  others = [entry for entry in group.entries if entry is not reference]
  rows = []
  for index, label in enumerate(group.labels):
    cells = [label]
    for entry in group.entries:
      values = [matrix[index, index] for matrix in continual_metrics.matrices(entry.record)]
      cells.append(ranking.mean_and_std(ranking.Estimate.of(values)))
    for entry in others if reference is not None else ():
      transfers = [
        continual_metrics.transfer_per_stage(mine, theirs)[index - 1]
        for mine, theirs in _paired_matrices(entry, reference)
      ]
      shown = index and transfers
      cells.append(
        ranking.mean_and_std(ranking.Estimate.of([v * PERCENT for v in transfers]))
        if shown
        else "-"
      )
    rows.append(tuple(cells))
  transfer_columns = [f"transfer, {entry.label} (%)" for entry in others] if reference else []
  return Table(
    f"{group.stream} ({group.family}, {group.profile} profile): each configuration's end-effector "
    f"error (mm) on {group.entries[0].record['task']} right after its own stage, mean ± std over "
    f"seeds; forward transfer against {REFERENCE}: the share of its error removed",
    ("configuration", *(entry.label for entry in group.entries), *transfer_columns),
    tuple(rows),
    label_columns=1,
  )


def _paired_matrices(entry: ContinualEntry, reference: ContinualEntry):
  """(entry's, reference's) error matrices of every seed both records hold."""
  theirs = {seed["seed"]: seed for seed in reference.record["per_seed"]}
  return [
    (continual_metrics.error_matrix(seed), continual_metrics.error_matrix(theirs[seed["seed"]]))
    for seed in entry.record["per_seed"]
    if seed["seed"] in theirs
  ]


def matrix_table(entry: ContinualEntry) -> Table:
  """One strategy's error matrix (normalised tip %, mean over seeds) as text."""
  labels = [c["label"] for c in entry.record["configurations"]]
  rows = tuple(
    (labels[stage], *("" if np.isnan(value) else f"{value:.2f}" for value in row))
    for stage, row in enumerate(entry.mean_matrix())
  )
  return Table(
    f"{entry.label}: normalised tip error (%) of each configuration (columns) after each stage "
    f"(rows), mean over {entry.record['seeds']} seed(s)",
    ("after", *labels),
    rows,
    label_columns=1,
  )


def matrix_values(entry: ContinualEntry) -> list[list[float | None]]:
  """``matrix_table``'s figures as numbers, ``None`` above the diagonal (for heat maps)."""
  return [
    [None if np.isnan(value) else float(value) for value in row] for row in entry.mean_matrix()
  ]


def explanation() -> str:
  """How to read the continual sections, for each page's introduction."""
  return (
    "Continual records (softbench run --protocol continual: a strategy learns a stream of arm "
    "configurations stage by stage) have a table per stream: each strategy's end-effector "
    "error after the last stage, its forgetting (largest rise of a configuration's error "
    "after it was learned) and its forward transfer against the independent networks, then "
    "each strategy's error matrix. docs/continual.md defines every figure."
  )
