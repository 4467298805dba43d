"""How densely each stage's babbling data covers the targets that stage is scored on.

For every configuration of a continual stream: its babbling dataset's training split (the data a
strategy learns that stage from, as `softbench run --protocol continual` collects it), the end
effector's positions in it, and the stream's task (the spiral) as the stage is scored on it:
how far each target lies from the nearest training sample, and how many samples lie within a
radius of it. A learner that maps targets to actions learns best where the samples are dense.

Usage:
  python docs/analysis/stream_coverage.py --streams degrade payload --family tendon \
      --profile default --radius-mm 5
"""

import argparse

import numpy as np
from scipy import spatial

from softbench import metrics
from softbench import profiles
from softbench import suite
from softbench.agents import learned
from softbench.continual import streams


def training_tips_mm(robot, profile: profiles.Profile) -> np.ndarray:
  """The end effector's positions (mm) reached in ``robot``'s babbling training split."""
  poses = learned.babbling_candidates(robot, profile).poses
  return poses[:, -1, :3] * metrics.MM_PER_M


def scored_targets_mm(robot, task: str, profile: profiles.Profile) -> np.ndarray:
  """The end effector's targets (mm) of the episode a stage is scored on (seed 0)."""
  env = suite.load(robot, task, seed=0, **suite.length_options(task, profile.episode_length))
  env.reset()
  targets = np.array([env.task.targets_at(step) for step in range(env.task.num_steps)])
  return targets[:, -1, :3] * metrics.MM_PER_M


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--streams", nargs="+", default=["degrade", "payload"])
  parser.add_argument("--family", default="tendon")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--radius-mm", type=float, default=5.0)
  args = parser.parse_args()
  profile = profiles.get(args.profile)
  print(
    f"{'stream':10s} {'configuration':14s} {'samples':>7s} {'spread (mm)':>11s} "
    f"{'nearest (mm)':>12s} {'max (mm)':>9s} {f'within {args.radius_mm:g} mm':>12s}"
  )
  for name in args.streams:
    stream = streams.get(name)
    for configuration in stream.configurations(args.family):
      tips = training_tips_mm(configuration.robot, profile)
      targets = scored_targets_mm(configuration.robot, stream.task, profile)
      tree = spatial.cKDTree(tips)
      nearest, _ = tree.query(targets)
      within = tree.query_ball_point(targets, args.radius_mm, return_length=True)
      spread = np.sqrt(np.mean(np.sum((tips - tips.mean(axis=0)) ** 2, axis=1)))
      print(
        f"{name:10s} {configuration.label:14s} {len(tips):7d} {spread:11.1f} "
        f"{nearest.mean():12.2f} {nearest.max():9.2f} {np.mean(within):12.2f}"
      )


if __name__ == "__main__":
  main()
