"""Scores any policy of a Gymnasium environment the leaderboard's way, e.g. a Stable-Baselines3
model::

  from softbench.envs import scoring
  score = scoring.score_policy(lambda obs: model.predict(obs, deterministic=True)[0],
                               "tendon-3", "spiral")
  print(score)  # position error 7.08 ± 1.12 mm (5 seeds), ...

Seed s is one episode from ``reset(seed=s)``, the episode ``softbench run`` scores its agent's
seed s on; each figure is the episode's mean over steps and scored modules of the errors that
``step`` reports in ``info`` (``environment.SoftArmEnv``), then mean ± standard deviation over
seeds (ddof 0), as the leaderboard ranks records. The task runs its full reference, as on the
``default`` and ``paper`` profiles.
"""

from collections.abc import Callable
import dataclasses

import numpy as np

from softbench import metrics
from softbench import profiles
from softbench import robots
from softbench.data import dataset
from softbench.envs import environment

DEFAULT_SEEDS = 5  # As the default and paper profiles score.
METRICS = {  # info's errors: how a score names them, and their units.
  "position_error_mm": ("position error", "mm"),
  "orientation_error_deg": ("orientation error", "deg"),
  "normalised_tip_error_percent": ("normalised tip error", "%"),
}


@dataclasses.dataclass(frozen=True)
class PolicyScore:
  """A policy's errors on one task: per seed, each metric's episode mean over steps and scored
  modules; ``of(metric)`` their mean and standard deviation over seeds."""

  robot: str
  task: str
  per_seed: tuple[dict[str, float], ...]

  def of(self, metric: str) -> metrics.Statistic:
    return metrics.Statistic.of([seed[metric] for seed in self.per_seed])

  def __str__(self) -> str:
    shown = [metric for metric in METRICS if metric in self.per_seed[0]]
    figures = (
      f"{METRICS[metric][0]} {self.of(metric).mean:.4g} ± {self.of(metric).std:.2g} "
      f"{METRICS[metric][1]}"
      for metric in shown
    )
    return f"{self.task} on {self.robot}: {', '.join(figures)} ({len(self.per_seed)} seeds)"


def score_policy(
  policy: Callable[[np.ndarray | dict], np.ndarray],
  robot: str | robots.SoftArm,
  task: str,
  seeds: int = DEFAULT_SEEDS,
  **options,
) -> PolicyScore:
  """``policy(observation) -> action`` scored on ``task`` of ``robot`` over seeds 0..seeds-1;
  ``options``: ``SoftArmEnv``'s (``observation="dict"``, the task's options).

  Raises:
    ValueError: a bad robot, task, option or seed count (one line).
  """
  dataset.check_count("seeds", seeds, profiles.MAX_SEEDS)
  env = environment.SoftArmEnv(robot, task, **options)
  per_seed = []
  for seed in range(seeds):
    observation, _ = env.reset(seed=seed)
    steps, done = [], False
    while not done:
      observation, _, terminated, truncated, info = env.step(policy(observation))
      steps.append(info)
      done = terminated or truncated
    per_seed.append(
      {
        metric: float(np.mean([step[metric] for step in steps], axis=0).mean())
        for metric in METRICS
        if metric in steps[0]
      }
    )
  env.close()
  return PolicyScore(env.robot.name, task, tuple(per_seed))
