"""Control steps per second of the vector environment against a single environment
(pytest-benchmark; run with `make bench`).

Each round steps ``ROUND_STEPS`` control steps of tendon-3's spiral on ``num_envs`` arms of
``SoftArmVectorEnv`` (the ``cpu`` backend on every core) and then of one ``SoftArmEnv``;
``extra_info`` holds both rates and their ratio. Goal (issue 64): at least 1.8
times the single environment's control steps per second on a 2-core machine.
"""

import os
import time

import gymnasium
import numpy as np
import pytest

import softbench.envs

ROBOT, TASK = "tendon-3", "spiral"
ROUND_STEPS = 4  # Control steps per round (per arm), of each environment.
ROUNDS = 5
EPISODE_STEPS = 2 * ROUND_STEPS * (ROUNDS + 1)  # No episode ends within the benchmark.


def make_single():
  env = gymnasium.make(softbench.envs.env_id(ROBOT, TASK), length=EPISODE_STEPS)
  env.reset(seed=0)
  return env


@pytest.mark.parametrize("num_envs", [2, 4, 8])
def test_vector_env_control_steps_per_second(benchmark, tmp_path_factory, monkeypatch, num_envs):
  """Each round steps the vector env, then the single env, ROUND_STEPS steps each: the machine's
  speed drifts (by a factor of 1.6 within minutes here), so the two are timed side by side."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "home"))
  env = gymnasium.make_vec(
    softbench.envs.env_id(ROBOT, TASK), num_envs, backend="cpu", length=EPISODE_STEPS
  )
  env.reset(seed=0)
  single = make_single()
  actions = np.zeros(env.action_space.shape, np.float32)
  seconds = {"vector": 0.0, "single": 0.0}

  def timed(name, step, action):
    start = time.perf_counter()
    for _ in range(ROUND_STEPS):
      step(action)
    seconds[name] += time.perf_counter() - start

  def both():
    timed("vector", env.step, actions)
    timed("single", single.step, actions[0])

  benchmark.pedantic(both, rounds=ROUNDS, iterations=1)
  vector_rate = num_envs * ROUND_STEPS * ROUNDS / seconds["vector"]
  single_rate = ROUND_STEPS * ROUNDS / seconds["single"]
  benchmark.extra_info.update(
    cores=os.cpu_count(),
    vector_control_steps_per_second=vector_rate,
    single_control_steps_per_second=single_rate,
    ratio_to_single_env=vector_rate / single_rate,
  )
