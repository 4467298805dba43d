"""Physics speed of every benchmark robot (pytest-benchmark; run with `make bench`).

Goal (issue 2): tendon-5 at least 10x faster than real time on one core.
"""

import mujoco
from mujoco import rollout
import numpy as np
import pytest

from softbench import robots

_SIMULATED_SECONDS = 2.0  # (s) Simulated time per benchmark round, under random actuation.


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_physics_steps_per_second(benchmark, name):
  robot = robots.make(name)
  model = robot.compile()
  data = mujoco.MjData(model)
  steps_per_action = int(round(robot.control_timestep / model.opt.timestep))
  periods = max(1, int(round(_SIMULATED_SECONDS / robot.control_timestep)))
  actions = np.random.default_rng(0).uniform(-1, 1, (periods, robot.action_dim))
  controls = np.repeat(robot.action_to_ctrl(actions), steps_per_action, axis=0)[None]
  state = np.empty(mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
  mujoco.mj_getState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
  benchmark(rollout.rollout, model, data, state[None], controls)
  seconds = benchmark.stats.stats.mean
  benchmark.extra_info["steps_per_second"] = controls.shape[1] / seconds
  benchmark.extra_info["real_time_factor"] = controls.shape[1] * model.opt.timestep / seconds
