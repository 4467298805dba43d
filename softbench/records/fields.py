"""What every kind of result record shares: the JSON Schema of its provenance, agent, profile,
seed and integrity fields, and the checks of those fields that a schema cannot make.

``records`` (``softbench run``'s records) and ``records.exp1s`` (``softbench run --protocol
exp1s``'s) build their schemas from these parts, so that the two kinds cannot drift apart.
"""

from collections.abc import Callable
import datetime
from typing import NoReturn

from softbench import profiles
from softbench import robots
from softbench.robots import versions

INTEGRITY_FIELD = "sha256"
METRICS = ("position_mm", "orientation_deg", "normalised_tip_percent")  # Every record kind's.
ERROR_SOURCES = ("physics", "model", "open-loop")
"""What a learned controller's error input is computed from (a record's ``eval_mode``): the
measured pose, the learned forward model's prediction, or nothing (``softbench.agents.learned``)."""
HELPER_TARGETS = ("complete", "nearest", "hold", "share")
"""How a learned agent completes a target that gives only part of the arm's pose (a record's
``helpers``; ``softbench.agents.learned``, ``softbench.agents.completion``)."""
AGENT_PATTERN = r"^[a-z0-9][a-z0-9_.-]*$"
ROBOT_PATTERN = robots.NAME_PATTERN
MAX_ERROR = 1e6
"""Bound on every error in a record (mm, deg, %, pose MSE). The arms are at most 0.5 m long, so
real errors stay below a few thousand; the bound refuses absurd values (1e308 would overflow the
sums of the consistency checks and the means of the pages)."""
MAX_WALL_TIME_S = 1e9  # (s) About 32 years: bounds the wall time likewise.

Refuse = Callable[[str], NoReturn]
"""Raises the record's error with a one-line message (the caller adds the file's name)."""


def non_negative(maximum: float = MAX_ERROR) -> dict:
  """A number from 0 to ``maximum``."""
  return {"type": "number", "minimum": 0, "maximum": maximum}


PHYSICS_FIELD = "physics"
"""The physics version a record was simulated with (``softbench.robots.versions``); records made
before there were versions (up to 2026-12-06) lack it and are v0."""
PHYSICS_BEFORE_VERSIONS = versions.FIRST


def physics_of(record: dict) -> str:
  """The physics version of a checked record."""
  return record.get(PHYSICS_FIELD, PHYSICS_BEFORE_VERSIONS)


WEIGHTS_FIELD = "weights"
"""The optional section that names, per seed, the sha256 of each weight file behind its scores."""
SHA256_PATTERN = "^[0-9a-f]{64}$"


def weights() -> dict:
  """The ``weights`` section (``softbench.zoo.weights_section``): per seed, the data-home path
  of each file the seed's agent was made of (checkpoint, forward models) and its sha256."""
  return {
    "type": "object",
    "required": ["per_seed"],
    "additionalProperties": False,
    "properties": {
      "per_seed": {
        "type": "array",
        "minItems": 1,
        "items": {
          "type": "object",
          "required": ["seed", "files"],
          "additionalProperties": False,
          "properties": {
            "seed": {"type": "integer", "minimum": 0},
            "files": {
              "type": "object",
              "minProperties": 1,
              "additionalProperties": {"type": "string", "pattern": SHA256_PATTERN},
            },
          },
        },
      }
    },
  }


def section() -> dict:
  """An extra field: allowed only as a JSON object (a fault, an adaptive schedule, ...)."""
  return {"type": "object"}


def properties() -> dict:
  """The schema of the fields every record has, by name."""
  return {
    "softbench_version": {"type": "string", "minLength": 1},
    "git_commit": {"type": ["string", "null"]},
    "agent": {"type": "string", "pattern": AGENT_PATTERN, "maxLength": 64},
    "profile": {"enum": list(profiles.PROFILES)},
    "profile_settings": {
      "type": "object",
      "required": ["name"],
      "properties": {"name": {"type": "string"}},
    },
    "seeds": {"type": "integer", "minimum": 1},
    "wall_time_s": non_negative(MAX_WALL_TIME_S),
    "date": {"type": "string", "format": "date-time"},
    "machine": {"type": "object"},
    PHYSICS_FIELD: {"enum": list(versions.VERSIONS)},
    INTEGRITY_FIELD: {"type": "string", "pattern": "^[0-9a-f]{64}$"},
  }


OPTIONAL_FIELDS = (PHYSICS_FIELD,)  # Of ``properties``: every record kind may lack them.


def check(record: dict, refuse: Refuse, seed_entries: int | None = None) -> None:
  """One entry per seed (``seed_entries`` entries where given), no seed twice, the profile's
  settings under its name, a dated record, weights named once per seed of the record."""
  per_seed = record["per_seed"]
  if seed_entries is not None and len(per_seed) != seed_entries:
    refuse(f"per_seed has {len(per_seed)} entries, {seed_entries} expected")
  if seed_entries is None and len(per_seed) != record["seeds"]:
    refuse(f"seeds is {record['seeds']} but per_seed has {len(per_seed)} entries")
  numbers = [entry["seed"] for entry in per_seed]
  if len(set(numbers)) != len(numbers):
    refuse(f"per_seed repeats a seed ({numbers})")
  if record["profile_settings"]["name"] != record["profile"]:
    refuse(
      f"profile_settings.name {record['profile_settings']['name']!r} is not the profile "
      f"{record['profile']!r}"
    )
  try:
    date = datetime.datetime.fromisoformat(record["date"])
  except ValueError:
    refuse(f"date {record['date']!r} is not an ISO 8601 date and time")
  if date.tzinfo is None:
    refuse(f"date {record['date']!r} has no time zone")
  weighed = [entry["seed"] for entry in record.get(WEIGHTS_FIELD, {}).get("per_seed", [])]
  if len(set(weighed)) != len(weighed) or any(seed >= record["seeds"] for seed in weighed):
    refuse(f"weights names seeds {weighed}: repeated, or beyond the record's {record['seeds']}")
