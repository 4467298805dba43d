"""Makes ``cable_equilibria.json``: the cable plugin's equilibrium tip positions (physics v0), which
``tests/test_rod.py`` holds the plugin-free rod to on any MuJoCo.

For every tendon arm N = 1 .. 5 of both families: random two-axis actions (uniform in [-1, 1] on
every entry, numpy's default_rng(seed)) each held from rest with gravity, tips read after
``HOLD_S``. An action whose tips still move by more than ``SETTLED_MM`` between ``HOLD_S`` and
twice that is no equilibrium (the arm keeps oscillating where cables press on their holes' edges)
and is replaced by the next draw; the file counts those.

Run it on the old stack, where the plugin exists: .venv-v0/bin/python tests/data/cable_equilibria.py
"""

import datetime
import json
import pathlib
import sys

import mujoco
import numpy as np

from softbench import robots
from softbench.robots import measure
from softbench.robots import versions
from softbench.storage import write_atomically

ROBOTS = tuple(f"{family}-{n}" for family in robots.TENDON_FAMILY_NAMES for n in range(1, 6))
ACTIONS_PER_ROBOT = 8
HOLD_S = 4.0  # (s)
SETTLED_MM = 1e-3  # (mm) Largest tip movement between HOLD_S and 2 HOLD_S of an equilibrium.
SEED = 0
PATH = pathlib.Path(__file__).with_suffix(".json")


def equilibria(name: str) -> dict:
  """Settled actions and the cable plugin's tips (modules, 3) in m for ``name``."""
  arm = robots.make(name, backbone="cable")
  rng = np.random.default_rng(SEED)
  actions, tips, unsettled = [], [], 0
  while len(actions) < ACTIONS_PER_ROBOT:
    action = rng.uniform(-1.0, 1.0, arm.action_dim)
    trajectory = measure.tip_trajectory(arm, action, 2 * HOLD_S)
    held = trajectory[int(round(HOLD_S / arm.timestep)) - 1]
    if np.abs(trajectory[-1] - held).max() * 1e3 > SETTLED_MM:
      unsettled += 1
      continue
    actions.append(action.tolist())
    tips.append(held.tolist())
  return {"actions": actions, "tips_m": tips, "unsettled_draws": unsettled}


def main() -> None:
  if not versions.cable_plugin_available():
    sys.exit(f"error: {versions.cable_plugin_missing()}")
  reference = {
    "made_with": f"mujoco {mujoco.__version__}, backbone cable (physics v0)",
    "date": datetime.date.today().isoformat(),
    "hold_s": HOLD_S,
    "settled_mm": SETTLED_MM,
    "seed": SEED,
    "robots": {},
  }
  for name in ROBOTS:
    reference["robots"][name] = equilibria(name)
    print(name, reference["robots"][name]["unsettled_draws"], "unsettled draws", flush=True)
  write_atomically(PATH, json.dumps(reference, indent=1) + "\n")


if __name__ == "__main__":
  main()
