"""SMPL (the paper's method): a progressive network with one LSTM column per module, trained
module by module in closed loop; earlier columns are frozen when the next one trains."""

from softbench.agents import learned


def build(robot, seed, profile, show_progress=False):
  return learned.build_agent("smpl", robot, seed, profile, per_module=True,
                             show_progress=show_progress)
