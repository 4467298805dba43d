"""Continual result records (``softbench run --protocol continual``): their JSON Schema and the
checks that the schema cannot make. ``records`` reads, seals and writes them like run records.

A record (format ``softbench-continual-result``, version 1) holds provenance, the ``stream``, its
tendon ``family``, the strategy (``agent``), the scored ``task``, the stream's ``configurations``
(label, robot, faults, payload), the profile, and per seed one entry per stage (in order): what
the stage trained on and how (``trained_on``, ``epochs``, ``best_validation_loss``,
``validation_curve``, ``training_seconds``), the strategy's size (``parameters``,
``parameters_trained``, ``carried_values``), model-level scores of configurations 0..s
(``model_pose_mse``, ``model_action_mse``) and their physics ``scores`` (end effector's position
in mm, orientation in deg, normalised tip in %, averaged over the episode). The layout is
``softbench.runners.continual_stream``'s, which writes these records.
"""

import math

from softbench import metrics
from softbench import robots
from softbench.records import fields as record_fields
from softbench.records.fields import METRICS

FORMAT = "softbench-continual-result"
VERSION = 1
PROTOCOL = "continual"
_TIP_TOLERANCE = 1e-9  # Relative: normalised tip error against position error / robot length.
_COUNT = {"type": "integer", "minimum": 0}
_LOSS = record_fields.non_negative()


def schema() -> dict:
  """The JSON Schema (draft 2020-12) of a continual record."""
  non_negative = record_fields.non_negative()
  scores = {
    "type": "object",
    "additionalProperties": False,
    "required": list(METRICS),
    "properties": {name: non_negative for name in METRICS},
  }
  losses = {"type": "array", "items": _LOSS}
  stage = {
    "type": "object",
    "additionalProperties": False,
    "required": [
      "stage",
      "trained_on",
      "epochs",
      "best_validation_loss",
      "validation_curve",
      "training_seconds",
      "parameters",
      "parameters_trained",
      "carried_values",
      "model_pose_mse",
      "model_action_mse",
      "scores",
    ],
    "properties": {
      "stage": _COUNT,
      "trained_on": {"type": "array", "items": _COUNT, "uniqueItems": True},
      "epochs": {"type": "array", "items": {"type": "integer", "minimum": 1}},
      "best_validation_loss": losses,
      "validation_curve": {"type": "array", "items": losses},
      "training_seconds": record_fields.non_negative(record_fields.MAX_WALL_TIME_S),
      "parameters": {"type": "integer", "minimum": 1},
      "parameters_trained": _COUNT,
      "carried_values": {"type": "integer", "minimum": 1},
      "model_pose_mse": losses,
      "model_action_mse": losses,
      "scores": {"type": "array", "items": scores, "minItems": 1},
    },
  }
  configuration = {
    "type": "object",
    "additionalProperties": False,
    "required": ["label", "robot", "faults", "payload_kg"],
    "properties": {
      "label": {"type": "string", "minLength": 1},
      "robot": {"type": "string", "pattern": record_fields.ROBOT_PATTERN},
      "faults": {"type": "array", "items": {"type": "string"}},
      "payload_kg": record_fields.non_negative(),
    },
  }
  seed = {
    "type": "object",
    "additionalProperties": False,
    "required": ["seed", "stages"],
    "properties": {
      "seed": {"type": "integer", "minimum": 0},
      "stages": {"type": "array", "items": stage, "minItems": 1},
    },
  }
  properties = {
    "format": {"const": FORMAT},
    "version": {"const": VERSION},
    "protocol": {"const": PROTOCOL},
    "stream": {"type": "string", "pattern": record_fields.AGENT_PATTERN},
    "family": {"enum": list(robots.TENDON_FAMILY_NAMES)},
    "task": {"type": "string", "minLength": 1},
    "configurations": {"type": "array", "items": configuration, "minItems": 1},
    "per_seed": {"type": "array", "items": seed, "minItems": 1},
    **record_fields.properties(),
  }
  return {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "softbench continual result record",
    "type": "object",
    "required": [name for name in properties if name not in record_fields.OPTIONAL_FIELDS],
    "properties": properties,
    "additionalProperties": record_fields.section(),
  }


def check(record: dict, refuse: record_fields.Refuse) -> None:
  """What the schema cannot say: a stage per configuration, in order, each scoring (and scoring
  at model level) configurations 0..s, its curves one per fit, configurations it trained on that
  exist, and normalised tip errors that follow from the position errors."""
  record_fields.check(record, refuse)
  count = len(record["configurations"])
  lengths_mm = []
  for configuration in record["configurations"]:
    try:
      lengths_mm.append(robots.length(configuration["robot"]) * metrics.MM_PER_M)
    except ValueError as error:
      refuse(f"configurations: {error}")
  for index, entry in enumerate(record["per_seed"]):
    stages = entry["stages"]
    if len(stages) != count:
      refuse(f"per_seed[{index}] has {len(stages)} stages for {count} configurations")
    for stage, summary in enumerate(stages):
      where = f"per_seed[{index}].stages[{stage}]"
      if summary["stage"] != stage:
        refuse(f"{where}.stage is {summary['stage']}, {stage} expected")
      for name in ("scores", "model_pose_mse", "model_action_mse"):
        if len(summary[name]) != stage + 1:
          refuse(f"{where}.{name} has {len(summary[name])} entries, {stage + 1} expected")
      fits = {len(summary[name]) for name in ("epochs", "best_validation_loss", "validation_curve")}
      if len(fits) != 1:
        refuse(f"{where}: epochs, best_validation_loss and validation_curve differ in length")
      if any(c >= count for c in summary["trained_on"]):
        refuse(f"{where}.trained_on {summary['trained_on']} names no configuration")
      for c, scores in enumerate(summary["scores"]):
        expected = scores["position_mm"] / lengths_mm[c] * metrics.PERCENT
        if not math.isclose(
          scores["normalised_tip_percent"], expected, rel_tol=_TIP_TOLERANCE, abs_tol=_TIP_TOLERANCE
        ):
          refuse(
            f"{where}.scores[{c}]: normalised_tip_percent {scores['normalised_tip_percent']} is "
            f"not position_mm / the configuration's length ({expected})"
          )
