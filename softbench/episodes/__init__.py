"""What happened in one episode of a task: the targets shown, the poses reached and the actions.

Written by ``softbench.runners.evaluation.run_episode``; read by the records, plots, videos and the
episode snapshots, none of which need the agents that produced it.
"""

import dataclasses

import numpy as np

from softbench import metrics


@dataclasses.dataclass(frozen=True)
class Episode:
  """What happened in one episode: targets shown and poses reached, step by step."""

  task: str
  scored_modules: tuple[int, ...]
  targets: np.ndarray  # (steps, scored modules, 6 or 3)
  achieved: np.ndarray  # (steps, scored modules, 6)
  poses: np.ndarray  # (steps + 1, num_modules, 6), every module, the start first
  actions: np.ndarray  # (steps, action_dim)
  rewards: np.ndarray  # (steps,)

  def score(self, robot_length: float) -> metrics.TrackingScore:
    return metrics.score(self.achieved, self.targets, robot_length)
