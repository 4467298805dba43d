"""The bilstm baseline: a bidirectional LSTM over the last 15 inputs, one centralised model for
the whole arm, trained in the same closed loop as SMPL."""

from smpl import baselines
from softbench.agents import learned

LEARNER = learned.Learner("bilstm", per_module=False, make_model=baselines.BiLSTMInverse)


def build(robot, seed, profile, show_progress=False):
  return learned.build_agent(LEARNER.name, robot, seed, profile, LEARNER.per_module,
                             LEARNER.make_model, show_progress)
