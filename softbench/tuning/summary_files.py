"""A study's summary file: where it goes, writing it, and adopting its best values as the agent's;
and the figures of a trial that a summary reports."""

import json
import math
import pathlib

import optuna

from softbench import storage
from softbench.agents import hyperparameters
from softbench.tuning import definition

SUMMARY_FOLDER = "tuning"  # Study summaries, under the data home.


def summary_path(settings: definition.TuneSettings) -> pathlib.Path:
  return storage.softbench_home() / SUMMARY_FOLDER / f"{settings.study_name}.json"


def write_summary(study_summary: dict, path: pathlib.Path) -> None:
  storage.write_atomically(path, json.dumps(study_summary, indent=2, allow_nan=False) + "\n")


def adopt(study_summary: dict, path: pathlib.Path | None = None) -> None:
  """Commits the study's best values as the agent's values on its robot, with the summary
  (less its trial table)."""
  if study_summary["best"] is None:
    raise ValueError(f"study {study_summary['study']!r} has no complete trial to adopt")
  compact = {key: value for key, value in study_summary.items() if key != "trial_table"}
  hyperparameters.adopt(
    study_summary["agent"], study_summary["robot"], study_summary["best"]["params"], compact, path
  )


def seconds(trial: optuna.trial.FrozenTrial) -> float:
  if trial.datetime_start is None or trial.datetime_complete is None:
    return 0.0
  return (trial.datetime_complete - trial.datetime_start).total_seconds()


def finite(value: float | None) -> float | None:
  """``value``, or None where it is missing or not finite (JSON has no infinity)."""
  return value if value is not None and math.isfinite(value) else None
