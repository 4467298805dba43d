"""``random``: uniform random actions in [-1, 1], a sanity check.

The actions come from the ``RANDOM_AGENT_STREAM`` seed stream, restarted at every ``reset``, so an
agent of a given seed acts the same sequence in every episode.
"""

import numpy as np

from softbench import profiles
from softbench.agents import base
from softbench.data import seeding
from softbench.robots import base as robot_base


class RandomAgent(base.Agent):
  """Acts i.i.d. uniform actions in [-1, 1]^action_dim."""

  def __init__(self, robot: robot_base.SoftArm, seed: int):
    super().__init__(robot, seed)
    self._rng = seeding.rng(seed, seeding.RANDOM_AGENT_STREAM)

  def reset(self, episode: base.EpisodeInfo) -> None:
    self._rng = seeding.rng(self.seed, seeding.RANDOM_AGENT_STREAM)

  def act(self, observation: dict) -> np.ndarray:
    return self._rng.uniform(-1.0, 1.0, self.robot.action_dim)


def build(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool = False
) -> base.Agent:
  del profile, show_progress  # Nothing to train.
  return RandomAgent(robot, seed)
