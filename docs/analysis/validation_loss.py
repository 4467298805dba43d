"""Each seed's validation and test loss of centralised learned agents, from cached checkpoints.

The loss is the one early stopping reads: the closed-loop action MSE through the seed's frozen
forward model, in normalised units, the VAE's KL term left out. Set beside the seeds' tracking
errors in physics, it shows whether the windows' loss tells good controllers from bad ones. Agents
that are not cached yet are trained first, as `softbench run` would.

Usage:
  python docs/analysis/validation_loss.py --agents vae-lstm lstm mlp --robot pneumatic-433 \
      --profile paper --seeds 5
"""

import argparse

from smpl import fitting
from smpl import training
from softbench import agents
from softbench import profiles
from softbench import robots
from softbench.learning import inverse as inverse_training
from softbench.tuning import study


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument(
    "--agents", nargs="+", default=["vae-lstm", "lstm", "mlp"], help="centralised learned agents"
  )
  parser.add_argument("--robot", default="pneumatic-433")
  parser.add_argument("--profile", default="paper")
  parser.add_argument("--seeds", type=int, default=5)
  args = parser.parse_args()

  arm, profile = robots.make(args.robot), profiles.get(args.profile)
  for name in args.agents:
    learner = study.learner(name) if agents.describe(name).learned else None
    if learner is None or learner.per_module:
      raise SystemExit(f"{name} is not a centralised learned agent")
    views = learner.views(arm)
    for seed in range(args.seeds):
      agent = agents.make(name, arm.name, seed, profile.name)
      (windows,), (forward,) = inverse_training.trained_forward_models(arm, views, seed, profile)

      def loss(batch, inverse=agent.inverse, forward=forward):
        return training.inverse_model_loss(inverse, forward, batch, include_aux_loss=False)

      validation = fitting.evaluate_loss(agent.inverse, loss, windows.validation)
      test = fitting.evaluate_loss(agent.inverse, loss, windows.test)
      print(
        f"{name} seed {seed}: validation loss {validation:.4f}, test loss {test:.4f}", flush=True
      )


if __name__ == "__main__":
  main()
