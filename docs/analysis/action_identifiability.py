"""How much of each babbling action the arm's poses determine.

A probe network (MLP, 2 x 256 tanh units) learns action a_s from poses x_s and x_{s+1} on a
dataset's training split; the action variance it leaves unexplained on the validation split (at
its best epoch) estimates a floor that an inverse model reading those poses cannot beat. Two
views: every module's poses to all actions (what the centralised baselines read), and modules
1..k's poses to module k's actions (what SMPL's column k reads, its own and, through the
laterals, the earlier columns'). The residual's main direction in each module's actions is
printed too: on pneumatic-433's module 1 it is the alternating combination of the four bellows,
which moves the tip plate nowhere.

Usage (datasets collected before, e.g. by `softbench run --profile paper`):
  python docs/analysis/action_identifiability.py pneumatic-433 tendon-3 [--samples 14000]
"""

import argparse

import numpy as np
import torch

from softbench import data
from softbench import robots

PROBE_UNITS = 256
PROBE_EPOCHS = 150
PROBE_BATCH = 64
PROBE_LEARNING_RATE = 1e-3


def split_arrays(
  dataset: data.Dataset, split: str, modules: int, actions: slice
) -> tuple[np.ndarray, np.ndarray]:
  """(poses x_s and x_{s+1} of modules 1..``modules``, flattened; actions a_s[actions]) of one
  split, every piece end to end."""
  inputs, targets = [], []
  for piece in data.split_pieces(dataset.episode_lengths)[split]:
    poses, piece_actions = piece.recording(dataset)
    poses, steps = poses[:, :modules], len(piece_actions)
    inputs.append(np.concatenate([poses[:-1].reshape(steps, -1), poses[1:].reshape(steps, -1)], 1))
    targets.append(piece_actions[:, actions])
  return np.concatenate(inputs), np.concatenate(targets)


def print_split_statistics(dataset: data.Dataset) -> None:
  """Each split's tip position (mean and spread, mm) and action mean and spread: the contiguous
  blocks come from the same distribution."""
  for split in data.SPLITS:
    inputs, actions = split_arrays(dataset, split, dataset.num_modules, slice(None))
    tip = inputs[:, -6:-3] * 1000.0  # x_{s+1} of the last module: its position, m to mm.
    print(
      f"  {split:10} tip mean {tip.mean(0)} mm, spread {tip.std(0)} mm; "
      f"actions mean {actions.mean():.4f}, spread {actions.std():.4f}"
    )


def probe(dataset: data.Dataset, modules: int, actions: slice, seed: int) -> dict:
  """Trains the probe; returns the validation residuals at its best epoch and both losses."""
  torch.manual_seed(seed)
  train_inputs, train_actions = split_arrays(dataset, "train", modules, actions)
  validation_inputs, validation_actions = split_arrays(dataset, "validation", modules, actions)
  mean, std = train_inputs.mean(0), train_inputs.std(0) + 1e-9
  tensor = lambda array: torch.as_tensor(array, dtype=torch.float32)
  x_train = tensor((train_inputs - mean) / std)
  x_validation = tensor((validation_inputs - mean) / std)
  a_train, a_validation = tensor(train_actions), tensor(validation_actions)
  network = torch.nn.Sequential(
    torch.nn.Linear(x_train.shape[1], PROBE_UNITS),
    torch.nn.Tanh(),
    torch.nn.Linear(PROBE_UNITS, PROBE_UNITS),
    torch.nn.Tanh(),
    torch.nn.Linear(PROBE_UNITS, a_train.shape[1]),
  )
  optimiser = torch.optim.Adam(network.parameters(), PROBE_LEARNING_RATE)
  best = {"validation": np.inf}
  for epoch in range(PROBE_EPOCHS):
    for batch in torch.randperm(len(x_train)).split(PROBE_BATCH):
      optimiser.zero_grad()
      torch.mean((network(x_train[batch]) - a_train[batch]) ** 2).backward()
      optimiser.step()
    with torch.no_grad():
      residuals = (network(x_validation) - a_validation).numpy()
      train_loss = torch.mean((network(x_train) - a_train) ** 2).item()
    if np.mean(residuals**2) < best["validation"]:
      best = {
        "epoch": epoch,
        "validation": float(np.mean(residuals**2)),
        "train": train_loss,
        "residuals": residuals,
      }
  best["action_variance"] = validation_actions.var(0)
  return best


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("robots", nargs="+")
  parser.add_argument("--samples", type=int, default=14_000)
  parser.add_argument("--data-seed", type=int, default=0)
  parser.add_argument("--seed", type=int, default=0, help="the probe's initialisation seed")
  args = parser.parse_args()
  torch.set_num_threads(1)
  np.set_printoptions(precision=3, suppress=True)
  for robot in args.robots:
    dataset = data.load(robot, args.samples, args.data_seed)
    slices = robots.make(robot).module_action_slices()
    print(f"{robot} ({args.samples} samples), the splits:")
    print_split_statistics(dataset)
    result = probe(dataset, len(slices), slice(None), args.seed)
    mse = np.mean(result["residuals"] ** 2, axis=0)
    print(
      f"{robot} ({args.samples} samples), every module's poses to all actions: best epoch "
      f"{result['epoch']}, action MSE train {result['train']:.4f}, "
      f"validation {result['validation']:.4f}"
    )
    print(f"  validation MSE per action      {mse}")
    print(f"  fraction of variance left      {mse / result['action_variance']}")
    for module, actions in enumerate(slices, start=1):
      variances, directions = np.linalg.eigh(np.cov(result["residuals"][:, actions].T))
      print(
        f"  module {module}: residual variance {variances[-1]:.4f} along "
        f"{directions[:, -1] * np.sign(directions[0, -1])}, "
        f"{variances[:-1].sum():.4f} in the other directions"
      )
    for module, actions in enumerate(slices, start=1):
      column = probe(dataset, module, actions, args.seed)
      left = np.mean(column["residuals"] ** 2, axis=0) / column["action_variance"]
      print(
        f"  modules 1..{module}'s poses to module {module}'s actions (SMPL's column "
        f"{module}): best epoch {column['epoch']}, action MSE train {column['train']:.4f}, "
        f"validation {column['validation']:.4f}, fraction of variance left {left}"
      )


if __name__ == "__main__":
  main()
