"""Motor-babbling throughput on all cores (pytest-benchmark; run with `make bench`).

Each round collects a fresh short dataset laid out like the default one (10 episodes side by
side), chunk files and final verification included. Goal (issue): the default 14,000 samples in
under 3 min for tendon-3 and under 10 min for tendon-5.
"""

import itertools
import os

import pytest

from softbench import data

_SAMPLES = 100  # Per round: 10 episodes of 10 samples.
_EPISODES = 10  # As in the default collection (14,000 samples in episodes of 1,400).
_ROUNDS = 3


@pytest.mark.parametrize("name", ["tendon-3", "tendon-5", "pneumatic-433"])
def test_babbling_samples_per_second(benchmark, tmp_path, name):
  workers = os.cpu_count() or 1
  homes = (tmp_path / str(round_index) for round_index in itertools.count())

  def fresh_home():
    return (), {"home": next(homes)}

  def collect(home):
    return data.collect(
      name,
      samples=_SAMPLES,
      workers=workers,
      home=home,
      progress=False,
      episode_length=_SAMPLES // _EPISODES,
    )

  benchmark.pedantic(collect, setup=fresh_home, rounds=_ROUNDS, iterations=1)
  samples_per_second = _SAMPLES / benchmark.stats.stats.mean
  benchmark.extra_info["workers"] = min(workers, _EPISODES)
  benchmark.extra_info["samples_per_second"] = samples_per_second
  benchmark.extra_info["default_collection_s"] = data.DEFAULT_SAMPLES / samples_per_second
