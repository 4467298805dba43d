"""How much a module's motion depends on the actuation of the modules after it.

SMPL's forward model k predicts module k's next pose from its pose and the actuation of modules 1..k
(the paper's design, ``data.View.module``); it cannot see what the distal modules do. This trains
that forward model (as the agents train theirs: ``inverse_training.forward_config``, the profile's
epochs and patience) and, beside it, one that also reads the distal modules' actuation, on the same
babbling windows (the profile's sample count, data seed 0), and prints both validation losses (pose
MSE, normalised units, at the best epoch) and their ratio; for the last module the two are the same
model, ratio 1. A ratio near 1 says the distal actuation adds little to predict module k; a large
one says module k moves with actions its column never sees (on tendon-N, whose distal cables cross
the proximal modules).

Usage (datasets collected before, e.g. by `softbench run` on the same profile):
  python docs/analysis/forward_coupling.py tendon-3 tendon-local-3 [--profile default] [--seed 0]
"""

import argparse

import torch

from softbench import data
from softbench import profiles
from softbench import robots
from softbench.learning import inverse as inverse_training
from softbench.learning import protocols


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("robots", nargs="+")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seed", type=int, default=0, help="the forward models' seed")
  args = parser.parse_args()
  torch.set_num_threads(1)
  profile = profiles.get(args.profile)
  config = inverse_training.forward_config(args.seed, profile)
  for name in args.robots:
    robot, dataset = robots.make(name), data.load(name, profile.samples, inverse_training.DATA_SEED)
    for module in range(1, robot.num_modules + 1):
      losses = [
        protocols.prepare_column(
          robot, view, dataset, config, torch.device("cpu")
        ).forward_training.best_validation_loss
        for view in (
          data.View.module(robot, module),
          data.View.module_reading_every_actuation(robot, module),
        )
      ]
      print(
        f"{name} module {module}: forward model's validation pose MSE from modules "
        f"1..{module}'s actuation {losses[0]:.5f}, from every module's {losses[1]:.5f} "
        f"(ratio {losses[0] / losses[1]:.2f})",
        flush=True,
      )


if __name__ == "__main__":
  main()
