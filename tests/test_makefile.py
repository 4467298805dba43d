"""``make leaderboard``: every setting once, skipping those that already have a record."""

import os
import pathlib
import shutil
import subprocess

import pytest

from softbench import agents
from softbench import robots

MAKEFILE = pathlib.Path(__file__).parent.parent / "Makefile"
_RECORDING_SOFTBENCH = """#!/bin/sh
echo "$@" >> "$(dirname "$0")/calls.txt"
"""


def _variable(name: str) -> list[str]:
  """A ``NAME := words`` variable of the Makefile, as its words."""
  for line in MAKEFILE.read_text().splitlines():
    if line.startswith(f"{name} :="):
      return line.split(":=", 1)[1].split()
  raise KeyError(name)


@pytest.fixture
def checkout(tmp_path) -> pathlib.Path:
  """A folder with the Makefile, an installed-looking .venv whose softbench records its calls."""
  if shutil.which("make") is None:
    pytest.fail("make is not installed; the README's commands need it")
  shutil.copy(MAKEFILE, tmp_path / "Makefile")
  (tmp_path / "pyproject.toml").touch()
  (tmp_path / "constraints.txt").touch()
  venv_bin = tmp_path / ".venv" / "bin"
  venv_bin.mkdir(parents=True)
  softbench = venv_bin / "softbench"
  softbench.write_text(_RECORDING_SOFTBENCH)
  softbench.chmod(0o755)
  stamp = tmp_path / ".venv" / ".installed"
  stamp.touch()
  later = (tmp_path / "pyproject.toml").stat().st_mtime + 10
  os.utime(stamp, (later, later))  # Installed after pyproject.toml changed: make installs nothing.
  (tmp_path / "leaderboard" / "results").mkdir(parents=True)
  return tmp_path


def _fill(checkout: pathlib.Path) -> list[str]:
  subprocess.run(
    ["make", "--no-print-directory", "leaderboard", "PROFILE=paper"],
    cwd=checkout,
    check=True,
    capture_output=True,
    text=True,
    timeout=60,
  )
  return (checkout / ".venv" / "bin" / "calls.txt").read_text().splitlines()


def test_the_fill_runs_every_agent_on_every_task_then_exp1s_then_the_pages(checkout):
  calls = _fill(checkout)
  assert set(_variable("LEADERBOARD_AGENTS")) == set(agents.AGENTS)
  runs = [call for call in calls if "--task" in call]
  assert len(runs) == (
    len(_variable("LEADERBOARD_ROBOTS")) * len(_variable("LEADERBOARD_TASKS")) * len(agents.AGENTS)
  )
  assert all("--profile paper" in call for call in runs)
  exp1s = [call for call in calls if "--protocol exp1s" in call]
  assert exp1s == [
    f"run --protocol exp1s --family {family} --agent smpl --profile paper "
    f"--results leaderboard/results"
    for family in robots.TENDON_FAMILIES
  ]
  assert calls[-len(exp1s) - 1 : -1] == exp1s  # After every task's runs.
  assert calls[-1] == "leaderboard --results leaderboard/results --write"


def test_an_interrupted_fill_skips_the_settings_that_have_records(checkout):
  results = checkout / "leaderboard" / "results"
  (results / "smpl-tendon-3-spiral-paper-physics-2026-11-24T000000Z.json").touch()
  # Another profile's record does not count.
  (results / "lstm-tendon-3-spiral-default-physics-2026-11-24T000000Z.json").touch()
  (results / "smpl-exp1s-paper-2026-11-24T000000Z.json").touch()
  calls = _fill(checkout)
  assert not any("--robot tendon-3 --task spiral --agent smpl " in call for call in calls)
  assert sum("--robot tendon-3 --task spiral --agent lstm " in call for call in calls) == 1
  assert sum("--robot tendon-local-3 --task spiral --agent smpl " in call for call in calls) == 1
  # The tendon family's Exp1S record does not stand for the tendon-local family's.
  assert [call for call in calls if "exp1s" in call] == [
    "run --protocol exp1s --family tendon-local --agent smpl --profile paper "
    "--results leaderboard/results"
  ]
  assert calls[-1].startswith("leaderboard")
  (results / "smpl-exp1s-tendon-local-paper-2026-11-24T000000Z.json").touch()
  (checkout / ".venv" / "bin" / "calls.txt").unlink()
  assert not any("exp1s" in call for call in _fill(checkout))
