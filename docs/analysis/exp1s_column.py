"""One Exp1S column trained again under other settings, on the cached network's frozen columns.

Loads seed --seed's cached Exp1S network of --profile (it must exist: this script never trains a
whole sequence), keeps its columns 1 .. N-1 and configuration N's frozen forward model, and trains
a new column N as Exp1S does (same data, seed and initial weights, SMPL's committed
hyperparameters) once per --settings entry, for --epochs epochs with early stopping off. Each
entry is LEARNING_RATE:POSE_LOSS_WEIGHT ('tuned' for the committed learning rate; a pose-loss
weight above 0 adds that times the forward model's pose MSE to the loss, off in Exp1S and in the
paper). For each it prints the best validation loss and its epoch, the test windows' action and
pose MSE (normalised units, through the forward model) of the weights early stopping keeps, and
their end-effector error closed loop in physics on --tasks.

Usage:
  python docs/analysis/exp1s_column.py --configuration 3 --seed 0 --profile paper \
      --epochs 12 --settings tuned:0 0.001:0 tuned:1 tuned:10 --tasks spiral
"""

import argparse
import dataclasses

import torch

from smpl import progressive
from smpl import protocol as smpl_protocol
from smpl import windows as smpl_windows
from softbench import data
from softbench import profiles
from softbench import suite
from softbench.agents import hyperparameters
from softbench.learning import inverse as inverse_training
from softbench.learning import protocols
from softbench.runners import continual
from softbench.runners import evaluation


def _setting(text: str) -> tuple[str, float]:
  learning_rate, pose_loss_weight = text.split(":")
  return learning_rate, float(pose_loss_weight)


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--configuration", type=int, default=3, help="2 to 5 (tendon-N)")
  parser.add_argument("--seed", type=int, default=0)
  parser.add_argument("--profile", default="paper")
  parser.add_argument("--epochs", type=int, default=12)
  parser.add_argument(
    "--settings",
    type=_setting,
    nargs="+",
    default=[("tuned", 0.0)],
    help="LEARNING_RATE:POSE_LOSS_WEIGHT entries ('tuned' learning rate)",
  )
  parser.add_argument("--tasks", nargs="*", default=["spiral"])
  args = parser.parse_args()

  profile, stage = profiles.get(args.profile), args.configuration - 1
  column_views = protocols.get(continual.PROTOCOL).column_views()
  if not 1 <= stage < len(column_views):
    raise SystemExit(f"--configuration must be 2 to {len(column_views)}")
  path = continual.checkpoint_path(args.seed, profile)
  if not path.exists():
    raise SystemExit(f"no cached Exp1S network {path}; run softbench run --protocol exp1s first")
  model = continual.build(args.seed, profile)
  arm, view = column_views[stage]
  dataset = data.collect(
    arm, samples=profile.samples, seed=inverse_training.DATA_SEED, progress=False
  )
  windows = data.windows(dataset, view)
  forward = model.controllers[stage].forward.requires_grad_(False)
  task = smpl_protocol.ColumnTask(windows.train, windows.validation, windows.test, forward)
  trained = model.network.state_dict()
  _, tuned = inverse_training.training_configs(
    args.seed, profile, hyperparameters.values("smpl", model.arms[-1].name)
  )

  for learning_rate, pose_loss_weight in args.settings:
    network = progressive.ProgressiveLSTM()
    for controller in model.controllers[:stage]:
      earlier = controller.view
      network.add_column(
        smpl_windows.inverse_input_size(earlier.pose_size, earlier.action_size), earlier.action_size
      )
    network.load_state_dict({name: trained[name] for name in network.state_dict()})
    config = dataclasses.replace(
      tuned,
      max_epochs=args.epochs,
      patience=args.epochs + 1,
      learning_rate=tuned.learning_rate if learning_rate == "tuned" else float(learning_rate),
      pose_loss_weight=pose_loss_weight,
    )
    label = f"learning rate {config.learning_rate:.3g}, pose-loss weight {pose_loss_weight:g}"
    report = lambda epoch: print(
      f"{label}: epoch {epoch.epoch + 1}: training loss "
      f"{epoch.train_loss:.4f}, validation {epoch.validation_loss:.4f}",
      flush=True,
    )
    result = smpl_protocol.train_next_column(network, task, config, torch.device("cpu"), report)
    network.requires_grad_(False).eval()
    score = smpl_protocol.evaluate_column(network, stage, task.test, forward)
    print(
      f"{label}: best validation {result.best_validation_loss:.4f} at epoch "
      f"{result.best_epoch + 1}; test action MSE {score.action_mse:.4f}, pose MSE "
      f"{score.pose_mse:.4f}",
      flush=True,
    )
    retrained = dataclasses.replace(model, network=network)
    agent = retrained.agent(args.configuration, args.seed)
    for name in args.tasks:
      env = suite.load(
        arm, name, seed=args.seed, **suite.length_options(name, profile.episode_length)
      )
      episode = evaluation.run_episode(env, agent, name)
      score = continual.end_effector_scores(episode, arm.length)
      print(
        f"{label}: {arm.name} {name}, closed loop in physics: end effector "
        f"{score['position_mm']:.2f} mm, {score['orientation_deg']:.2f} deg, "
        f"{score['normalised_tip_percent']:.2f} %",
        flush=True,
      )


if __name__ == "__main__":
  main()
