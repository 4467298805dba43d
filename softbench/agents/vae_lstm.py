"""The vae-lstm baseline: a variational LSTM, one centralised model for the whole arm, trained in the
same closed loop as SMPL."""

from smpl import baselines
from softbench.agents import learned


def build(robot, seed, profile, show_progress=False):
  return learned.build_agent("vae-lstm", robot, seed, profile, per_module=False,
                             make_model=baselines.VAELSTMInverse, show_progress=show_progress)
