"""Control steps per second of the vector environment against a single environment
(pytest-benchmark; run with `make bench`).

Each round steps ``ROUND_STEPS`` control steps of tendon-3's spiral on ``num_envs`` arms of
``SoftArmVectorEnv`` (the ``cpu`` backend on every core) and, in the same run, of one
``SoftArmEnv``; ``extra_info`` holds both rates and their ratio. Goal (issue 64): at least 1.8
times the single environment's control steps per second on a 2-core machine.
"""

import os
import time

import gymnasium
import numpy as np
import pytest

import softbench.envs

ROBOT, TASK = "tendon-3", "spiral"
ROUND_STEPS = 6  # Control steps per round (per arm).
ROUNDS = 3
EPISODE_STEPS = 2 * ROUND_STEPS * (ROUNDS + 1)  # No episode ends within the benchmark.


def single_env_steps_per_second() -> float:
  env = gymnasium.make(softbench.envs.env_id(ROBOT, TASK), length=EPISODE_STEPS)
  env.reset(seed=0)
  action = np.zeros(env.action_space.shape, np.float32)
  start = time.perf_counter()
  for _ in range(ROUND_STEPS * ROUNDS):
    env.step(action)
  return ROUND_STEPS * ROUNDS / (time.perf_counter() - start)


@pytest.mark.parametrize("num_envs", [2, 4, 8])
def test_vector_env_control_steps_per_second(benchmark, tmp_path_factory, monkeypatch, num_envs):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "home"))
  env = gymnasium.make_vec(
    softbench.envs.env_id(ROBOT, TASK), num_envs, backend="cpu", length=EPISODE_STEPS
  )
  env.reset(seed=0)
  actions = np.zeros(env.action_space.shape, np.float32)

  def steps():
    for _ in range(ROUND_STEPS):
      env.step(actions)

  benchmark.pedantic(steps, rounds=ROUNDS, iterations=1)
  vector_rate = num_envs * ROUND_STEPS / benchmark.stats.stats.mean
  single_rate = single_env_steps_per_second()
  benchmark.extra_info.update(
    cores=os.cpu_count(),
    vector_control_steps_per_second=vector_rate,
    single_control_steps_per_second=single_rate,
    ratio_to_single_env=vector_rate / single_rate,
  )
