"""SMPL (the paper's method): a progressive network with one LSTM column per module, trained
module by module in closed loop; earlier columns are frozen when the next one trains."""

from softbench.agents import learned

LEARNER = learned.Learner("smpl", per_module=True)


def build(robot, seed, profile, show_progress=False):
  return learned.build_agent(LEARNER.name, robot, seed, profile, LEARNER.per_module,
                             LEARNER.make_model, show_progress)
