"""Set-up speed of environments (pytest-benchmark; run with `make bench`): loading a task whose
reference the data home holds, and calibrating the bend amplitude a new reference is traced at.
"""

import pytest

from softbench import robots
from softbench import suite
from softbench.suite import references

_STEPS = 4  # Control steps of the loaded episode: loading, not stepping, is measured.
_CALIBRATION_ROUNDS = 3


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_task_load_seconds(benchmark, tmp_path, monkeypatch, name):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  suite.load(name, "circle", length=_STEPS)  # Simulates and caches the reference once.
  environment = benchmark(suite.load, name, "circle", length=_STEPS)
  assert environment.task.num_steps == _STEPS


@pytest.mark.parametrize("name", [family.example for family in robots.FAMILIES])
def test_bend_amplitude_calibration_seconds(benchmark, name):
  arm = robots.make(name)
  calibrate = references.bend_amplitude.__wrapped__  # Past the per-process cache.
  amplitude = benchmark.pedantic(calibrate, args=(arm,), rounds=_CALIBRATION_ROUNDS, iterations=1)
  benchmark.extra_info["amplitude"] = amplitude
