"""Exp1S records built by hand in the shape ``continual.execute`` gives (no training): errors drawn
per configuration, normalised tip errors that follow from them, triangular forgetting matrices."""

import numpy as np

from softbench import metrics
from softbench import profiles
from softbench import robots
from softbench.robots import versions
from softbench.runners import continual

ROBOTS = tuple(f"tendon-{n}" for n in range(1, 6))
DATE = "2026-01-02T03:04:05+00:00"


def exp1s_record(
  seeds: int = 2,
  profile: str = "tiny",
  date: str = DATE,
  robot_names: tuple[str, ...] = ROBOTS,
  scale: float = 1.0,
) -> dict:
  """An unsealed Exp1S record with errors drawn per seed and configuration (times ``scale``)."""
  rng = np.random.default_rng(seeds)
  lengths_mm = {name: robots.make(name).length * metrics.MM_PER_M for name in robot_names}
  size = len(robot_names)
  per_seed = []
  for seed in range(seeds):
    scores = {loop: {task: [] for task in continual.TASKS} for loop in continual.LOOPS}
    for loop in continual.LOOPS:
      for task in continual.TASKS:
        for name in robot_names:
          position = float(rng.uniform(0.1, 10.0)) * scale
          scores[loop][task].append(
            {
              "position_mm": position,
              "orientation_deg": float(rng.uniform(0.1, 5.0)),
              "normalised_tip_percent": position / lengths_mm[name] * metrics.PERCENT,
            }
          )
    tip = [entry["normalised_tip_percent"] for entry in scores["closed"][continual.FORGETTING_TASK]]
    model = [float(value) for value in rng.uniform(1e-4, 1e-2, size)]
    per_seed.append(
      {
        "seed": seed,
        "scores": scores,
        "forgetting_model_pose_mse": [
          [model[c] if c <= s else None for c in range(size)] for s in range(size)
        ],
        "forgetting_tip_percent": [
          [tip[c] if c <= s else None for c in range(size)] for s in range(size)
        ],
      }
    )
  settings = profiles.get(profile)
  return {
    "format": continual.RECORD_FORMAT,
    "version": continual.RECORD_VERSION,
    "softbench_version": "0.1.0",
    "git_commit": None,
    "date": date,
    "machine": {"platform": "test"},
    "physics": versions.current().name,  # As softbench run stamps its records here.
    "protocol": continual.PROTOCOL,
    "agent": "smpl",
    "robots": list(robot_names),
    "tasks": list(continual.TASKS),
    "profile": profile,
    "profile_settings": {"name": settings.name, "samples": settings.samples},
    "seeds": seeds,
    "per_seed": per_seed,
    "wall_time_s": 12.5,
  }
