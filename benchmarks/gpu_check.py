"""The GPU check of issue 64, one short script for a lent device machine (docs/compute.md, "On a
GPU"): physics throughput of ``ArmBatch`` for N = 1 .. 4,096 arms of tendon-3 and pneumatic-433
on MuJoCo Warp (and the CPU backend beside it), the Warp backend's distance to the serial path,
and a short SAC training through the vector environment where Stable-Baselines3 is installed.

  python benchmarks/gpu_check.py --out $OUT/gpu_check.json [--budget-s 420] [--sac-steps 4000]

Each measurement holds one control period (after a warm-up period, which captures the CUDA
graph) and reports physics steps per second = arms x MuJoCo steps per period / seconds. The script
stops starting new measurements when ``--budget-s`` is spent, and writes what it has after every
one, so a run cut short still returns its figures.
"""

import argparse
import json
import pathlib
import platform
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from softbench import robots  # noqa: E402
from softbench.robots import batch  # noqa: E402
from softbench.robots import batch_warp  # noqa: E402
from softbench.robots import physics as arm_physics  # noqa: E402

ROBOTS = ("tendon-3", "pneumatic-433")
WARP_ARMS = (1, 16, 256, 1024, 4096)
CPU_ARMS = (1, 16)
SAC_STEPS = 4_000  # Environment steps of the short training (8 arms at once).


def period_seconds(arms: batch.ArmBatch, draw: np.random.Generator) -> float:
  """Seconds of one control period of every arm, after a warm-up period."""
  shape = (arms.num_arms, arms.robot.action_dim)
  arms.hold(draw.uniform(-1, 1, shape))
  start = time.perf_counter()
  arms.hold(draw.uniform(-1, 1, shape))
  arms.poses()  # Waits for the device.
  return time.perf_counter() - start


def parity(name: str) -> float:
  """Largest tip distance (m) of the Warp backend to the serial path after one period."""
  arm = robots.make(name)
  action = np.random.default_rng(0).uniform(-1, 1, (1, arm.action_dim))
  warp_arms = batch_warp.WarpArmBatch(arm, 1)
  warp_arms.hold(action)
  physics = arm_physics.SoftArmPhysics.from_robot(arm)
  physics.set_action(action[0])
  physics.step(warp_arms.steps_per_period)
  return float(np.abs(warp_arms.poses()[0, :, :3] - physics.module_poses()[:, :3]).max())


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--out", type=pathlib.Path, required=True)
  parser.add_argument("--budget-s", type=float, default=420.0)
  parser.add_argument("--sac-steps", type=int, default=SAC_STEPS)
  args = parser.parse_args()
  deadline = time.monotonic() + args.budget_s
  report = {"machine": platform.node(), "python": platform.python_version(), "throughput": []}
  report["warp"] = batch_warp.cuda_available()

  def save() -> None:
    args.out.write_text(json.dumps(report, indent=1))

  draw = np.random.default_rng(0)
  backends = [("cpu", CPU_ARMS)] + ([("warp", WARP_ARMS)] if report["warp"] else [])
  for name in ROBOTS:
    if report["warp"]:
      report.setdefault("parity_m", {})[name] = parity(name)
    for backend, counts in backends:
      for count in counts:
        if time.monotonic() > deadline:
          report["cut_short"] = True
          save()
          return
        with batch.make(robots.make(name), count, backend=backend) as arms:
          seconds = period_seconds(arms, draw)
          steps = count * arms.steps_per_period
        report["throughput"].append(
          {
            "robot": name,
            "backend": backend,
            "arms": count,
            "period_s": seconds,
            "physics_steps_per_s": steps / seconds,
            "control_steps_per_s": count / seconds,
          }
        )
        print(json.dumps(report["throughput"][-1]), flush=True)
        save()
  try:
    from softbench import profiles  # noqa: PLC0415  Needs torch and Stable-Baselines3.
    from softbench.agents import sac  # noqa: PLC0415
  except ImportError as error:
    report["sac"] = f"skipped: {error}"
  else:
    sac.STEPS["tiny"] = args.sac_steps
    started = time.perf_counter()
    trained = sac.train(robots.make("tendon-3"), 0, profiles.get("tiny"))
    report["sac"] = {
      "environment_steps": trained["environment_steps"],
      "wall_time_s": time.perf_counter() - started,
    }
  save()


if __name__ == "__main__":
  main()
