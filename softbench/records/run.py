"""Run records (``softbench run``): their JSON Schema and the checks that the schema cannot make.
``records`` reads, seals and writes them like every other kind.

A record (format ``softbench-result``, version 2) holds provenance, settings and, per seed, the
errors of every scored module (``per_seed``); an adaptive activation record holds its scores in
its ``adaptive`` section instead.
"""

import math

from softbench import robots
from softbench import suite
from softbench.records import fields as record_fields
from softbench.records.fields import METRICS

FORMAT = "softbench-result"
VERSION = 2
_OPTIONAL_FIELDS = (
  "video",
  "faults",
  "zoo",
  "training",
  "helpers",
  "given",
  record_fields.WEIGHTS_FIELD,
  *record_fields.OPTIONAL_FIELDS,
)
ADAPTIVE_SECTION = "adaptive"  # softbench run --adaptive: per-target results, no per-seed ones.
_MEAN_TOLERANCE = 1e-9  # Relative: a seed's mean against the mean of its per-module values.


def schema() -> dict:
  """The JSON Schema (draft 2020-12) of a ``softbench run`` record, enums from the current
  registries."""
  non_negative = record_fields.non_negative()
  per_module = {"type": "array", "items": non_negative, "minItems": 1}
  metric = {
    "type": "object",
    "additionalProperties": False,
    "required": ["per_module", "per_module_std_over_steps", "mean"],
    "properties": {
      "per_module": per_module,
      "per_module_std_over_steps": per_module,
      "mean": non_negative,
    },
  }
  section = record_fields.section()
  seed = {
    "type": "object",
    "required": ["seed", "steps", "mean_reward", "position_mm", "normalised_tip_percent"],
    "properties": {
      "seed": {"type": "integer", "minimum": 0},
      "steps": {"type": "integer", "minimum": 1},
      "mean_reward": {"type": "number", "minimum": 0, "maximum": 1},
      **{name: metric for name in METRICS},
    },
    "additionalProperties": section,
  }
  properties = {
    "format": {"const": FORMAT},
    "version": {"const": VERSION},
    "robot": {"type": "string", "pattern": record_fields.ROBOT_PATTERN},
    "task": {"enum": list(suite.TASKS)},
    "eval_mode": {"enum": list(record_fields.ERROR_SOURCES)},
    "trajectory": {"type": ["string", "null"]},
    "given": {"type": "string", "minLength": 1},  # A custom trajectory's given part (Given.text).
    # How a learned agent completed partial targets (softbench.agents.fields.HELPER_TARGETS);
    # records before target completion (2026-12-03) held every module not given ("hold").
    "helpers": {"enum": list(record_fields.HELPER_TARGETS)},
    "scored_modules": {
      "type": "array",
      "items": {"type": "integer", "minimum": 1},
      "minItems": 1,
      "uniqueItems": True,
    },
    "per_seed": {"type": "array", "items": seed},  # Empty in adaptive activation records.
    "video": {"type": "string", "minLength": 1},
    "faults": {
      "type": "array",
      "items": {  # softbench.robots.faults.describe
        "type": "object",
        "required": ["module", "actuator", "gain", "text"],
        "properties": {
          "module": {"type": "integer", "minimum": 1},
          "actuator": {"type": "integer", "minimum": 0},
          "gain": {"type": "number", "minimum": 0, "maximum": 1},
          "text": {"type": "string"},
        },
      },
    },
    # The zoo files a run took instead of training (softbench.zoo.section).
    "zoo": {
      "type": "object",
      "required": ["files"],
      "properties": {
        "files": {"type": "array", "items": {"type": "string", "minLength": 1}, "minItems": 1}
      },
    },
    # The files each seed's agent was made of, with their sha256 (softbench.zoo.weights_section).
    record_fields.WEIGHTS_FIELD: record_fields.weights(),
    # What an agent that learns by acting spent per seed (softbench.agents.training_summary).
    "training": {
      "type": "object",
      "required": ["per_seed"],
      "properties": {
        "per_seed": {
          "type": "array",
          "items": {
            "type": "object",
            "required": ["seed"],
            "properties": {
              "seed": {"type": "integer", "minimum": 0},
              "environment_steps": {"type": "integer", "minimum": 1},
              "episodes": {"type": "integer", "minimum": 1},
              "wall_time_s": record_fields.non_negative(record_fields.MAX_WALL_TIME_S),
            },
          },
        }
      },
    },
    **record_fields.properties(),
  }
  return {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "softbench result record",
    "type": "object",
    "required": [name for name in properties if name not in _OPTIONAL_FIELDS],
    "properties": properties,
    "additionalProperties": section,
  }


def check(record: dict, refuse: record_fields.Refuse) -> None:
  """What the schema cannot say of a run record: counts that must agree, means that must
  follow."""
  adaptive = ADAPTIVE_SECTION in record
  if adaptive and record["per_seed"]:
    refuse(f"an {ADAPTIVE_SECTION} record holds its scores in that section; per_seed must be empty")
  record_fields.check(record, refuse, seed_entries=0 if adaptive else None)
  per_seed = record["per_seed"]
  try:
    num_modules = robots.num_modules(record["robot"])
  except ValueError as error:
    refuse(f"robot: {error}")
  if max(record["scored_modules"]) > num_modules:
    refuse(
      f"scored_modules {record['scored_modules']} name a module beyond {record['robot']}'s "
      f"{num_modules}"
    )
  if (record["trajectory"] is None) == (record["task"] == "custom"):
    refuse("trajectory goes with task custom, and task custom needs one")
  measured = [name for name in METRICS if per_seed and name in per_seed[0]]
  for index, entry in enumerate(per_seed):
    if [name for name in METRICS if name in entry] != measured:
      refuse(
        f"per_seed[{index}] has metrics {[n for n in METRICS if n in entry]}, per_seed[0] "
        f"has {measured}"
      )
    for name in measured:
      where = f"per_seed[{index}].{name}"
      for field in ("per_module", "per_module_std_over_steps"):
        if len(entry[name][field]) != len(record["scored_modules"]):
          refuse(
            f"{where}.{field} has {len(entry[name][field])} values for "
            f"{len(record['scored_modules'])} scored modules"
          )
      expected = math.fsum(entry[name]["per_module"]) / len(entry[name]["per_module"])
      if not math.isclose(
        entry[name]["mean"], expected, rel_tol=_MEAN_TOLERANCE, abs_tol=_MEAN_TOLERANCE
      ):
        refuse(
          f"{where}.mean {entry[name]['mean']} is not the mean of its per_module values "
          f"({expected})"
        )
