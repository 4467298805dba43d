"""The lstm baseline: a 2-layer LSTM, one centralised model for the whole arm, trained in the
same closed loop as SMPL."""

from smpl import baselines
from softbench.agents import learned


def build(robot, seed, profile, show_progress=False):
  return learned.build_agent("lstm", robot, seed, profile, per_module=False,
                             make_model=baselines.LSTMInverse, show_progress=show_progress)
