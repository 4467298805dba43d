"""``zero``: always the zero action, a sanity check: the arm relaxes towards its rest pose."""

import numpy as np

from softbench import profiles
from softbench.agents import base
from softbench.robots import base as robot_base


class ZeroAgent(base.Agent):
  """Acts ``zeros(action_dim)`` at every step."""

  def act(self, observation: dict) -> np.ndarray:
    return np.zeros(self.robot.action_dim)


def build(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool = False
) -> base.Agent:
  del profile, show_progress  # Nothing to train.
  return ZeroAgent(robot, seed)
