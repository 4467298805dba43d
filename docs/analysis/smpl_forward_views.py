"""SMPL trained through forward models that see every module's actuation: is its gap to the
centralised learners one of what its forward models see?

SMPL's column k trains in closed loop through a frozen forward model of module k that reads the
actuation of modules 1..k (``data.View.module``, the paper's design); on an arm whose modules
load one another (a bent distal module weighs on the proximal ones) that model cannot predict
what the distal modules do to module k. This trains SMPL as `softbench run` does (the profile's
dataset, the committed hyperparameters, the same seed, column by column in closed loop, the same
columns) once per --views entry: ``own`` is SMPL itself (it reproduces seed --seed of the
committed record of that setting to the digit, which checks the script), ``every`` trains each
column through a forward model of module k that also reads every other module's recorded
actuation (``data.View.module_reading_every_actuation``; cached in the data home beside the
others). The columns' inputs, and so the controller acting in physics, are the same for both;
each is scored closed loop in physics on --task. The agent's own checkpoint is neither read nor
written.

Usage (the forward models train first if the data home lacks them):
  python docs/analysis/smpl_forward_views.py --robot tendon-local-3 --profile default \
      --seeds 0 1 2 --views own every --task spiral
"""

import argparse
import time

from softbench import data
from softbench import profiles
from softbench import robots
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.learning import inverse as inverse_training
from softbench.runners import run
from softbench.runners import run_settings

VIEWS = {
  "own": data.View.module,  # Module k's forward model reads modules 1..k's actuation.
  "every": data.View.module_reading_every_actuation,  # ... and the distal modules' too.
}


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robot", default="tendon-local-3")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seeds", type=int, nargs="+", default=[0])
  parser.add_argument("--task", default="spiral")
  parser.add_argument("--views", nargs="+", choices=tuple(VIEWS), default=list(VIEWS))
  args = parser.parse_args()

  arm, profile = robots.make(args.robot), profiles.get(args.profile)
  params = hyperparameters.values("smpl", arm.name)
  settings = run_settings.settings(args.task, "smpl", args.robot, seeds=1, profile=args.profile)
  for seed in args.seeds:
    for name in args.views:
      views = [VIEWS[name](arm, module) for module in range(1, arm.num_modules + 1)]
      windows, forwards = inverse_training.trained_forward_models(arm, views, seed, profile)
      started = time.perf_counter()
      inverse, validation_loss = inverse_training.train_inverse(
        views, windows, forwards, seed, profile, True, None, params
      )
      trained_s = time.perf_counter() - started
      controllers = learned.controllers(views, forwards, [split.normalisation for split in windows])
      agent = learned.LearnedAgent(arm, seed, inverse.eval(), controllers)
      entry, _ = run.evaluate(agent, arm, settings, seed)
      position = entry["position_mm"]
      print(
        f"smpl forward views {name} {args.robot} {args.profile} seed {seed}: validation loss "
        f"{validation_loss:.5f}; {args.task} position error {position['mean']:.4f} mm, per "
        f"module {[round(x, 3) for x in position['per_module']]} (trained in {trained_s:.0f} s)",
        flush=True,
      )


if __name__ == "__main__":
  main()
