"""EWC's lambda chosen on validation data: a stream's first two stages, once per lambda.

Learns --stream's first configuration once (on --family, --profile, --seed, as ``softbench run
--protocol continual --agent ewc`` learns it), then for each --lambdas value learns the second
configuration with that weight of the consolidation penalty, from the same first-stage weights,
and prints one JSON line: the closed-loop action MSE (normalised units) on the validation windows
of the first and the second configuration, their mean, and the stage's seconds. Test windows and
physics are not read: the choice stays blind to what the records report.

Usage:
  python docs/analysis/ewc_lambda.py --lambdas 0 1e4 1e5 1e6 3e6 1e7 1e8
"""

import argparse
import copy
import json
import time

import torch

from smpl import rollout as smpl_rollout
from softbench import profiles
from softbench.continual import learning
from softbench.continual import streams
from softbench.continual.strategies import ewc


def main() -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--stream", default="grow")
  parser.add_argument("--family", default="tendon")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seed", type=int, default=0)
  parser.add_argument("--lambdas", type=float, nargs="+", default=[0.0, 1e5, 1e7])
  args = parser.parse_args()

  profile = profiles.get(args.profile)
  configurations = streams.get(args.stream).configurations(args.family)[:2]
  stages = learning.stage_data(configurations, args.seed, profile)
  strategy = ewc.ElasticWeightConsolidation(learning.setting(stages, args.seed, profile))

  def validation_mse(configuration: int) -> float:
    windows = stages[configuration].windows.validation
    with torch.no_grad():
      result = smpl_rollout.rollout(
        strategy.controller(configuration), windows, stages[configuration].forward, True
      )
    return torch.nn.functional.mse_loss(result.actions, windows.actions).item()

  strategy.grow(0)
  strategy.learn(0, stages, None)
  first_stage = copy.deepcopy(strategy.module.state_dict())
  strategy.grow(1)
  chosen = ewc.LAMBDA
  try:
    for value in args.lambdas:
      ewc.LAMBDA = value
      strategy.module.load_state_dict(first_stage, strict=False)  # Fisher filled by stage 2.
      started = time.perf_counter()
      strategy.learn(1, stages, None)
      first, second = validation_mse(0), validation_mse(1)
      print(
        json.dumps(
          {
            "lambda": value,
            "first": first,
            "second": second,
            "mean": (first + second) / 2,
            "seconds": round(time.perf_counter() - started, 1),
          }
        ),
        flush=True,
      )
  finally:
    ewc.LAMBDA = chosen


if __name__ == "__main__":
  main()
