"""SMPL with its columns trained together: is its gap to the centralised learners one of the order
its columns train in?

`softbench run` trains SMPL's columns one after another (the paper's progressive scheme): column 1
on module 1 alone, then frozen, column 2 beside it, and so on, each column's loss the action error
of its own module. So column 1 is fixed before any distal column exists. This trains the same
network (the paper's columns, the same seed's initial weights, the committed hyperparameters,
the same per-module forward models and closed-loop rollout, ``smpl.rollout.joint_rollout``) with
every column trainable at once on the mean action error over all modules, for up to as many
epochs as the columns get together (the profile's epochs times the modules), and scores it
closed loop in physics on --task beside the committed record of `softbench run`'s SMPL for the
same seed (read from --results). With --preceding acted, module k's forward model reads the
actions columns 1..k-1 just took instead of their modules' recorded actuation, so that in training
a proximal column's mistakes move the distal modules as they do in physics. Nothing is cached but
the forward models.

Usage (the forward models train first if the data home lacks them):
  python docs/analysis/smpl_joint_columns.py --robot tendon-local-3 --profile default \
      --seeds 0 1 2 --task spiral [--preceding acted]
"""

import argparse
import dataclasses
import time

import torch

from smpl import fitting
from smpl import training
from smpl import windows as smpl_windows
from softbench import leaderboard
from softbench import profiles
from softbench import records
from softbench import robots
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.agents import learners
from softbench.learning import inverse as inverse_training
from softbench.runners import run
from softbench.runners import run_settings


def check_preceding_is_proximal(windows: list) -> None:
  """Module k's recorded preceding actuation is modules 1..k-1's actions, normalised alike, as
  ``acted_preceding`` needs; raises otherwise."""
  for index, split in enumerate(windows):
    proximal = [earlier.train.actions for earlier in windows[:index]]
    expected = torch.cat(proximal, dim=-1) if proximal else split.train.preceding_actions
    if not torch.allclose(split.train.preceding_actions, expected, atol=1e-6):
      raise ValueError(f"module {index + 1}'s preceding actuation is not modules 1..{index}'s")


def recorded_score(folder: str, task: str, robot: str, profile: str, seed: int) -> str:
  """Seed ``seed``'s module-averaged position error in the newest record of SMPL on this
  setting, or "none" if there is no record (or it lacks the seed)."""
  found = [
    record
    for _, record in records.read_folder(folder)
    if tuple(record.get(key) for key in ("agent", "task", "robot", "profile", "eval_mode"))
    == ("smpl", task, robot, profile, "physics")
  ]
  seeds = max(found, key=lambda record: record["date"])["per_seed"] if found else []
  return f"{seeds[seed]['position_mm']['mean']:.4f} mm" if seed < len(seeds) else "none"


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robot", default="tendon-local-3")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seeds", type=int, nargs="+", default=[0])
  parser.add_argument("--task", default="spiral")
  parser.add_argument("--results", default=str(leaderboard.DEFAULT_RESULTS))
  parser.add_argument(
    "--preceding",
    choices=("recorded", "acted"),
    default="recorded",
    help="module k's forward model reads modules 1..k-1's recorded actuation (the paper's "
    "design) or the actions their columns just took",
  )
  args = parser.parse_args()

  arm, profile = robots.make(args.robot), profiles.get(args.profile)
  views = learners.views(arm, per_module=True)
  params = hyperparameters.values("smpl", arm.name)
  settings = run_settings.settings(args.task, "smpl", args.robot, seeds=1, profile=args.profile)
  device = fitting.default_device()
  for seed in args.seeds:
    windows, forwards = inverse_training.trained_forward_models(arm, views, seed, profile)
    check_preceding_is_proximal(windows)
    with fitting.seeded(seed, torch.device("cpu")):
      network, _ = inverse_training.untrained(views, True, None, params)
    network.requires_grad_(True)  # Adding a column froze the ones before it.
    _, config = inverse_training.training_configs(seed, profile, params)
    config = dataclasses.replace(config, max_epochs=profile.max_epochs * arm.num_modules)
    for model in forwards:
      model.to(device).eval()
    split = lambda part: smpl_windows.ModuleWindows(tuple(getattr(w, part) for w in windows))
    started = time.perf_counter()
    result = fitting.fit(
      network,
      training.joint_action_loss(
        network,
        forwards,
        feed_back_error=config.feed_back_error,
        acted_preceding=args.preceding == "acted",
      ),
      split("train"),
      split("validation"),
      config,
      device,
    )
    trained_s = time.perf_counter() - started
    trained = sum(p.numel() for p in network.parameters() if p.requires_grad)
    controllers = learned.controllers(views, forwards, [part.normalisation for part in windows])
    agent = learned.LearnedAgent(arm, seed, network.cpu().eval(), controllers)
    entry, _ = run.evaluate(agent, arm, settings, seed)
    position = entry["position_mm"]
    recorded = recorded_score(args.results, args.task, args.robot, args.profile, seed)
    print(
      f"smpl joint columns, {args.preceding} preceding actuation, {args.robot} {args.profile} "
      f"seed {seed}: validation loss "
      f"{result.best_validation_loss:.5f} after {result.epochs_run} epochs; {args.task} "
      f"position error {position['mean']:.4f} mm, per module "
      f"{[round(x, 3) for x in position['per_module']]} ({trained:,} parameters trained in "
      f"{trained_s:.0f} s; columns trained in order, the record: {recorded})",
      flush=True,
    )


if __name__ == "__main__":
  main()
