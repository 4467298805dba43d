"""Two robots side by side: each agent's error on both, as the leaderboard holds them.

Reads the records of a results folder (the newest per agent, profile and eval mode, as the pages
show them) and prints, for one profile and eval mode, a markdown table with a row per agent and a
column per task: the module-averaged position error (mm, mean ± std over seeds) on the first robot,
an arrow, the same on the second. Below it, per task and robot, the learned agents ranked by mean
error, so that one reads where SMPL (one column per module) stands against the centralised
learners. Written to compare the two tendon plants: tendon-3 routes distal cables through the
proximal modules, tendon-local-3 acts within each module as the paper's simulator does.

Usage:
  python docs/analysis/plant_comparison.py [--robots tendon-3 tendon-local-3] [--profile default]
      [--eval physics] [--results leaderboard/results] [--physics v0]
"""

import argparse
import pathlib

from softbench import agents
from softbench import leaderboard
from softbench import suite
from softbench.leaderboard import ranking

METRIC = "position_mm"


def estimates(
  board: ranking.Leaderboard, profile: str, eval_mode: str
) -> dict[tuple[str, str, str], ranking.Estimate]:
  """Position error by (robot, task, agent), plain tasks only, newest record of each setting."""
  found = {}
  for group in board.groups:
    if group.variant:
      continue
    for entry in group.entries:
      if entry.setting[1:] == (profile, eval_mode):
        found[group.robot, group.task, entry.setting[0]] = entry.estimates[METRIC]
  return found


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robots", nargs=2, default=["tendon-3", "tendon-local-3"])
  parser.add_argument("--profile", default="default")
  parser.add_argument("--eval", default="physics")
  parser.add_argument("--results", type=pathlib.Path, default=leaderboard.DEFAULT_RESULTS)
  parser.add_argument(
    "--physics", help="the records of this physics version (default: the newest among them)"
  )
  args = parser.parse_args()
  board = leaderboard.build(args.results)
  found = estimates(board.of_physics(args.physics or board.physics), args.profile, args.eval)
  tasks = [
    task
    for task in suite.TASKS
    if any((robot, task, agent) in found for robot in args.robots for agent in agents.AGENTS)
  ]
  first, second = args.robots
  print(
    f"position error (mm), {args.profile} profile, eval {args.eval}, mean ± std over seeds: "
    f"{first} -> {second}\n"
  )
  print("| agent | " + " | ".join(tasks) + " |")
  print("|---" * (len(tasks) + 1) + "|")
  for agent in agents.AGENTS:
    cells = [
      " -> ".join(
        ranking.mean_and_std(found[robot, task, agent]) if (robot, task, agent) in found else "-"
        for robot in args.robots
      )
      for task in tasks
    ]
    if any(cell != "- -> -" for cell in cells):
      print(f"| {agent} | " + " | ".join(cells) + " |")
  learned = [agent for agent in agents.AGENTS if agents.describe(agent).learned]
  print()
  for task in tasks:
    for robot in args.robots:
      ranked = sorted(
        (found[robot, task, agent].mean, agent)
        for agent in learned
        if (robot, task, agent) in found
      )
      print(
        f"{task} on {robot}, learned agents from best: "
        + ", ".join(f"{agent} {mean:.2f}" for mean, agent in ranked)
      )


if __name__ == "__main__":
  main()
