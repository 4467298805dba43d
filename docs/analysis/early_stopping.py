"""What early stopping on the action MSE costs in tracking: one seed of a centralised baseline.

Trains the agent's inverse model as `softbench run` does (the profile's dataset and cached
forward model, the committed hyperparameters, the same seed and closed loop) but with early
stopping off, keeps its weights after the epochs listed in --keep, and scores each set of weights,
and the best-validation weights that early stopping keeps, closed loop in physics on one task.

Usage:
  python docs/analysis/early_stopping.py --agent lstm --robot pneumatic-433 --task spiral \
      --seed 0 --profile paper --epochs 60 --keep 5 10 20 40 60
"""

import argparse
import copy
import dataclasses

import torch

from smpl import fitting
from smpl import training
from softbench import agents
from softbench import profiles
from softbench import robots
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.learning import inverse as inverse_training
from softbench.runners import run
from softbench.runners import run_settings
from softbench.tuning import study


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--agent", default="lstm", help="a centralised learned agent")
  parser.add_argument("--robot", default="pneumatic-433")
  parser.add_argument("--task", default="spiral")
  parser.add_argument("--seed", type=int, default=0)
  parser.add_argument("--profile", default="paper")
  parser.add_argument("--epochs", type=int, default=60)
  parser.add_argument("--keep", type=int, nargs="+", default=[5, 10, 20, 40, 60])
  args = parser.parse_args()

  arm, profile = robots.make(args.robot), profiles.get(args.profile)
  learner = study.learner(args.agent) if agents.describe(args.agent).learned else None
  if learner is None or learner.per_module:
    raise SystemExit(f"{args.agent} trains column by column; pick a centralised agent")
  (view,) = views = learner.views(arm)
  windows, forwards = inverse_training.trained_forward_models(arm, views, args.seed, profile)
  params = hyperparameters.values(args.agent, arm.name)
  _, config = inverse_training.training_configs(args.seed, profile, params)
  config = dataclasses.replace(config, max_epochs=args.epochs, patience=args.epochs + 1)
  with fitting.seeded(args.seed, torch.device("cpu")):
    inverse = inverse_training._inverse_model(views, False, learner.make_model, params)

  kept = {}

  def keep(report: fitting.EpochReport) -> None:
    epoch = report.epoch + 1  # Epochs trained so far.
    print(
      f"epoch {epoch}: training loss {report.train_loss:.4f}, "
      f"validation {report.validation_loss:.4f}",
      flush=True,
    )
    if epoch in args.keep:
      kept[f"after epoch {epoch}"] = copy.deepcopy(inverse.state_dict())

  result = training.train_inverse_model(
    inverse,
    forwards[0],
    windows[0].train,
    windows[0].validation,
    config,
    fitting.default_device(),
    keep,
    restart_diverged=True,
  )
  best = f"best validation (epoch {result.best_epoch + 1}, what early stopping keeps)"
  kept = {best: copy.deepcopy(inverse.state_dict()), **kept}
  settings = run_settings.settings(args.task, args.agent, args.robot, seeds=1, profile=args.profile)
  for label, state in kept.items():
    inverse.load_state_dict(state)
    inverse.eval()
    agent = learned.LearnedAgent(
      arm,
      args.seed,
      inverse,
      [learned.Controller(view, forwards[0].eval(), windows[0].normalisation)],
    )
    entry, _ = run.evaluate(agent, arm, settings, args.seed)
    position = entry["position_mm"]
    print(
      f"{args.agent} {args.robot} {args.task} seed {args.seed}, {label}: position error "
      f"{position['mean']:.2f} mm (per module {[round(x, 2) for x in position['per_module']]})",
      flush=True,
    )


if __name__ == "__main__":
  main()
