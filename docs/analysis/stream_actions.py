"""How hard a continual strategy drives each module, against the reference agent.

For each chosen configuration of a continual stream, right after the stage that learned it
(the strategy's cached stages, as `softbench run --protocol continual` trains them), and for the
`reference` agent, which plans every action on that configuration's own simulator: the
end-effector error (mm) of the stream's scored episode, and per module the mean |action|, its
largest value and the share of action entries above SATURATED. A module the strategy drives
less than the reference does is one its inverse model under-uses.

Usage:
  python docs/analysis/stream_actions.py --stream degrade --family tendon \
      --strategy independent --seeds 0 1 2 --configurations 3 4 --profile default
"""

import argparse

import numpy as np

from softbench import agents
from softbench import profiles
from softbench.continual import learning as continual_learning
from softbench.continual import streams
from softbench.runners import continual_stream

SATURATED = 0.95  # |action| (action units) above which an entry counts as at its bound.


def episode(agent, task: str, seed: int, profile: profiles.Profile):
  """The end-effector error (mm) and the actions (steps, action_dim) of ``agent``'s episode,
  scored as the continual records score it."""
  actions = []
  act = agent.act

  def recorded(observation):
    actions.append(np.asarray(act(observation), dtype=float))
    return actions[-1]

  agent.act = recorded
  scores = continual_stream.end_effector_episode(agent, task, seed, profile)
  return scores["position_mm"], np.array(actions)


def row(label: str, who: str, agent, task: str, seed: int, profile) -> str:
  """One printed row of ``agent``'s episode: the error, then each module's mean |action|, largest
  and saturated share."""
  error_mm, actions = episode(agent, task, seed, profile)
  magnitudes = np.abs(actions)
  ends = np.cumsum(agent.robot.actuators_per_module)
  modules = [
    f"m{number} {part.mean():.3f} {part.max():.3f} {np.mean(part > SATURATED):.3f}"
    for number, part in enumerate(np.split(magnitudes, ends[:-1], axis=1), start=1)
  ]
  return f"{label:14s} {who:12s} {seed:4d} {error_mm:10.4f}   " + "   ".join(modules)


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--stream", default="degrade")
  parser.add_argument("--family", default="tendon")
  parser.add_argument("--strategy", default="independent")
  parser.add_argument("--seeds", type=int, nargs="+", default=[0])
  parser.add_argument("--configurations", type=int, nargs="+", help="1-based; default: all")
  parser.add_argument("--profile", default="default")
  args = parser.parse_args()
  profile = profiles.get(args.profile)
  stream = streams.get(args.stream)
  configurations = stream.configurations(args.family)
  chosen = args.configurations or range(1, len(configurations) + 1)
  print(
    f"{'configuration':14s} {'agent':12s} {'seed':>4s} {'error (mm)':>10s}   "
    f"per module: mean |action|, largest, share above {SATURATED}"
  )
  for seed in args.seeds:  # One pass over the seed's cached stages.
    for strategy, stages, summary in continual_learning.learn(
      args.strategy, stream, args.family, seed, profile
    ):
      configuration = summary["stage"]
      if configuration + 1 not in chosen:
        continue
      label, robot = configurations[configuration].label, configurations[configuration].robot
      reference = agents.make("reference", robot, seed, profile)
      print(row(label, "reference", reference, stream.task, seed, profile), flush=True)
      agent = continual_stream.configuration_agent(
        strategy, stages[configuration], configuration, seed
      )
      print(row(label, args.strategy, agent, stream.task, seed, profile), flush=True)
      if configuration + 1 == max(chosen):
        break  # The later stages are not asked for.


if __name__ == "__main__":
  main()
