"""Exp1S result records (``softbench run --protocol exp1s``): their JSON Schema and the checks
that the schema cannot make. ``records`` reads, seals and writes them like run records.

A record (format ``softbench-exp1s-result``, version 2) holds provenance, settings and per seed:
``scores[loop][task]``, one entry per configuration (``robots``, in training order) with the end
effector's position (mm), orientation (deg) and normalised tip (%) errors averaged over the
episode; ``forgetting_model_pose_mse`` and ``forgetting_tip_percent``, stages x configurations,
``null`` exactly above the diagonal (a configuration not yet learned). Version 1 (before the
integrity hash) is refused. The layout is ``softbench.runners.continual``'s, which writes these
records.
"""

import math

import numpy as np

from softbench import metrics
from softbench import robots
from softbench.records import fields as record_fields
from softbench.records.fields import METRICS

FORMAT = "softbench-exp1s-result"
VERSION = 2  # 2: sealed with an integrity hash.
PROTOCOL = "exp1s"
DEFAULT_FAMILY = "tendon"  # The paper's Exp1S: tendon-1 .. tendon-5, cables routed through.
TASKS = ("babbling", "circle", "rectangle", "spiral")  # The paper's Exp1S table.
LOOPS = {"closed": "physics", "open": "open-loop"}  # Table label -> the agent's error source.
FORGETTING_TASK = "spiral"
MATRICES = ("forgetting_model_pose_mse", "forgetting_tip_percent")
_TIP_TOLERANCE = 1e-9  # Relative: normalised tip error against position error / robot length.


def schema() -> dict:
  """The JSON Schema (draft 2020-12) of an Exp1S record."""
  non_negative = record_fields.non_negative()
  configuration = {
    "type": "object",
    "additionalProperties": False,
    "required": list(METRICS),
    "properties": {name: non_negative for name in METRICS},
  }
  per_task = {
    "type": "object",
    "propertyNames": {"enum": list(TASKS)},
    "additionalProperties": {"type": "array", "items": configuration, "minItems": 1},
  }
  matrix = {
    "type": "array",
    "minItems": 1,
    "items": {"type": "array", "items": {"anyOf": [non_negative, {"type": "null"}]}},
  }
  seed = {
    "type": "object",
    "required": ["seed", "scores", *MATRICES],
    "properties": {
      "seed": {"type": "integer", "minimum": 0},
      "scores": {
        "type": "object",
        "additionalProperties": False,
        "required": list(LOOPS),
        "properties": {loop: per_task for loop in LOOPS},
      },
      **{name: matrix for name in MATRICES},
    },
    "additionalProperties": record_fields.section(),
  }
  properties = {
    "format": {"const": FORMAT},
    "version": {"const": VERSION},
    "protocol": {"const": PROTOCOL},
    "robots": {
      "type": "array",
      "minItems": 1,
      "uniqueItems": True,
      "items": {"type": "string", "pattern": record_fields.ROBOT_PATTERN},
    },
    "tasks": {"type": "array", "minItems": 1, "uniqueItems": True, "items": {"enum": list(TASKS)}},
    "per_seed": {"type": "array", "items": seed, "minItems": 1},
    **record_fields.properties(),
  }
  optional = {record_fields.WEIGHTS_FIELD: record_fields.weights()}
  return {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "softbench Exp1S result record",
    "type": "object",
    "required": [name for name in properties if name not in record_fields.OPTIONAL_FIELDS],
    "properties": {**properties, **optional},
    "additionalProperties": record_fields.section(),
  }


def check(record: dict, refuse: record_fields.Refuse) -> None:
  """What the schema cannot say: counts that agree, triangular matrices, the forgetting matrix's
  last row and the normalised tip errors that follow from the position errors."""
  record_fields.check(record, refuse)
  lengths_mm = {}
  for name in record["robots"]:
    try:
      lengths_mm[name] = robots.length(name) * metrics.MM_PER_M
    except ValueError as error:
      refuse(f"robots: {error}")
  if FORGETTING_TASK not in record["tasks"]:
    refuse(f"tasks {record['tasks']} lack {FORGETTING_TASK}, the task of the forgetting matrix")
  for index, entry in enumerate(record["per_seed"]):
    _check_scores(record, entry["scores"], f"per_seed[{index}].scores", lengths_mm, refuse)
    for name in MATRICES:
      _check_triangular(entry[name], len(record["robots"]), f"per_seed[{index}].{name}", refuse)
    closed = [
      scores["normalised_tip_percent"] for scores in entry["scores"]["closed"][FORGETTING_TASK]
    ]
    if entry["forgetting_tip_percent"][-1] != closed:
      refuse(
        f"per_seed[{index}].forgetting_tip_percent's last row "
        f"{entry['forgetting_tip_percent'][-1]} is not the closed-loop "
        f"{FORGETTING_TASK} normalised tip errors {closed}"
      )


def _check_scores(
  record: dict, scores: dict, where: str, lengths_mm: dict, refuse: record_fields.Refuse
) -> None:
  for loop, per_task in scores.items():
    if sorted(per_task) != sorted(record["tasks"]):
      refuse(
        f"{where}.{loop} has tasks {sorted(per_task)}, the record's tasks are "
        f"{sorted(record['tasks'])}"
      )
    for task, entries in per_task.items():
      if len(entries) != len(record["robots"]):
        refuse(
          f"{where}.{loop}.{task} has {len(entries)} entries for "
          f"{len(record['robots'])} configurations"
        )
      for configuration, (robot, entry) in enumerate(zip(record["robots"], entries)):
        expected = entry["position_mm"] / lengths_mm[robot] * metrics.PERCENT
        if not math.isclose(
          entry["normalised_tip_percent"], expected, rel_tol=_TIP_TOLERANCE, abs_tol=_TIP_TOLERANCE
        ):
          refuse(
            f"{where}.{loop}.{task}[{configuration}]: "
            f"normalised_tip_percent {entry['normalised_tip_percent']} is not "
            f"position_mm / {robot}'s length ({expected})"
          )


def _check_triangular(matrix: list, size: int, where: str, refuse: record_fields.Refuse) -> None:
  """Square with one row and column per configuration; null exactly above the diagonal."""
  if len(matrix) != size or any(len(row) != size for row in matrix):
    refuse(f"{where} is not {size} x {size} (one row per stage, one column per configuration)")
  for stage, row in enumerate(matrix):
    for configuration, value in enumerate(row):
      if (value is None) != (configuration > stage):
        expected = "null" if configuration > stage else "a number"
        refuse(
          f"{where}[{stage}][{configuration}] is {value}; {expected} expected "
          f"(null exactly above the diagonal)"
        )


def family(record: dict) -> str:
  """The tendon family of an Exp1S record's configurations."""
  return robots.family_of(record["robots"][0]).name


def mean_forgetting(record: dict) -> np.ndarray:
  """The physics forgetting matrix (stages x configurations, normalised tip error in %), mean
  over seeds; NaN for configurations not yet seen."""
  matrices = [
    [
      [np.nan if value is None else value for value in row]
      for row in seed["forgetting_tip_percent"]
    ]
    for seed in record["per_seed"]
  ]
  return np.mean(np.array(matrices, dtype=float), axis=0)
