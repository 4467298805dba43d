"""Reach error of learned agents with each way of completing the point into a whole-arm target.

One agent per name (trained with seed 0, or found in the data home) reaches the reach task's
points for environment seeds 0 .. N-1 with every ``--helpers`` mode (``complete``, ``nearest``,
``hold``, ``share``; see docs/target-completion.md), closed loop in physics. Per agent and mode:
median and quartiles over the targets of the position error of the reaching module's tip, as the
reach task scores it (the mean over the episode's steps), and at the episode's end, with the wall
time. Writes the table as JSON next to printing it.

Usage:
  python docs/analysis/reach_completion.py --robot pneumatic-433 --agents smpl,mlp --targets 20
"""

import argparse
import json
import pathlib
import time

import numpy as np

from softbench import agents
from softbench import suite
from softbench.records import fields
from softbench.runners import evaluation

QUARTILES = (25, 50, 75)  # (%) Percentiles reported over targets.


def errors_mm(agent, robot: str, targets: int) -> np.ndarray:
  """(targets, 2): each target's episode-mean and final position error (mm) of the reaching
  module's tip."""
  rows = []
  for seed in range(targets):
    env = suite.load(robot, "reach", seed=seed)
    episode = evaluation.run_episode(env, agent, "reach")
    tip = episode.poses[-1][env.task.module - 1, :3]
    final = np.linalg.norm(tip - episode.targets[-1][0, :3]) * 1000.0
    rows.append((episode.score(agent.robot.length).average("position_mm").mean, final))
  return np.array(rows)


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robot", default="pneumatic-433")
  parser.add_argument("--agents", default=",".join(agents.babbling_learners()))
  parser.add_argument("--profile", default="default")
  parser.add_argument("--targets", type=int, default=20)
  parser.add_argument("--out", help="the JSON file (default: reach-completion-ROBOT-PROFILE.json)")
  args = parser.parse_args()
  table = {}
  for name in args.agents.split(","):
    agent = agents.make(name, args.robot, 0, args.profile)
    for helpers in fields.HELPER_TARGETS:
      started = time.perf_counter()
      errors = errors_mm(agent.with_acting(helper_targets=helpers), args.robot, args.targets)
      row = {
        "episode_mean_mm": np.percentile(errors[:, 0], QUARTILES).round(2).tolist(),
        "final_mm": np.percentile(errors[:, 1], QUARTILES).round(2).tolist(),
        "seconds": round(time.perf_counter() - started, 1),
      }
      table[f"{name} {helpers}"] = row
      print(
        f"{name} {helpers}: episode-mean {row['episode_mean_mm']} mm, final {row['final_mm']} mm "
        f"(quartiles over {args.targets} targets), {row['seconds']} s",
        flush=True,
      )
  out = pathlib.Path(args.out or f"reach-completion-{args.robot}-{args.profile}.json")
  out.write_text(json.dumps(table, indent=1) + "\n")
  print(f"wrote {out}")


if __name__ == "__main__":
  main()
