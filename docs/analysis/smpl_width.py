"""SMPL with wider or deeper columns: is its gap to the centralised learners one of capacity?

SMPL's columns keep the paper's size (2 LSTM layers of 32 units each), while the tuned LSTM
baseline has 2 x 64 for the whole arm. This trains SMPL's columns as `softbench run` does (the
profile's dataset and cached per-module forward models, the committed hyperparameters, the same
seed, column by column in closed loop) once per --columns entry WIDTHxLAYERS, and scores each
closed loop in physics on --task. The entry 32x2 is SMPL itself: it reproduces seed --seed of the
committed record of that setting to the digit, which checks the script. Nothing is cached; the
agent's own checkpoint is neither read nor written.

Usage (the forward models train first if the data home lacks them):
  python docs/analysis/smpl_width.py --robot tendon-local-3 --profile default --seed 0 \
      --columns 32x2 64x2 128x2 --task spiral
"""

import argparse
import time
from unittest import mock

from smpl import progressive
from softbench import profiles
from softbench import robots
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.agents import learners
from softbench.learning import inverse as inverse_training
from softbench.runners import run
from softbench.runners import run_settings


def _columns(text: str) -> tuple[int, int]:
  width, layers = text.split("x")
  return int(width), int(layers)


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robot", default="tendon-local-3")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seed", type=int, default=0)
  parser.add_argument("--task", default="spiral")
  parser.add_argument("--columns", type=_columns, nargs="+", default=[(32, 2), (64, 2)])
  args = parser.parse_args()

  arm, profile = robots.make(args.robot), profiles.get(args.profile)
  views = learners.views(arm, per_module=True)
  windows, forwards = inverse_training.trained_forward_models(arm, views, args.seed, profile)
  params = hyperparameters.values("smpl", arm.name)
  settings = run_settings.settings(args.task, "smpl", args.robot, seeds=1, profile=args.profile)
  for width, layers in args.columns:

    class Columns(progressive.ProgressiveLSTM):
      def __init__(self, hidden_size: int = width, num_lstm_layers: int = layers) -> None:
        super().__init__(hidden_size, num_lstm_layers)

    started = time.perf_counter()
    with mock.patch.object(progressive, "ProgressiveLSTM", Columns):
      inverse, validation_loss = inverse_training.train_inverse(
        views, windows, forwards, args.seed, profile, True, None, params
      )
    trained_s = time.perf_counter() - started
    inverse.eval()
    controllers = learned.controllers(views, forwards, [split.normalisation for split in windows])
    agent = learned.LearnedAgent(arm, args.seed, inverse, controllers)
    entry, _ = run.evaluate(agent, arm, settings, args.seed)
    position = entry["position_mm"]
    parameters = sum(p.numel() for p in inverse.parameters())
    print(
      f"smpl {width}x{layers} ({parameters:,} parameters) {args.robot} {args.profile} seed "
      f"{args.seed}: validation loss {validation_loss:.5f}; {args.task} position error "
      f"{position['mean']:.4f} mm, per module {[round(x, 3) for x in position['per_module']]}"
      f" (trained in {trained_s:.0f} s)",
      flush=True,
    )


if __name__ == "__main__":
  main()
