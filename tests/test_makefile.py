"""``make leaderboard``: every setting once, skipping those that already have a record."""

import os
import pathlib
import shutil
import subprocess

import pytest

from softbench import agents
from softbench import cli
from softbench import robots
from softbench.leaderboard import grid

MAKEFILE = pathlib.Path(__file__).parent.parent / "Makefile"
# Answers the grid's questions as `softbench leaderboard --grid AXIS` does (checked below), and
# records every other call.
_RECORDING_SOFTBENCH = """#!/bin/sh
if [ "$1 $2" = "leaderboard --grid" ]; then
  case "$3" in
{answers}
  esac
  exit 0
fi
echo "$@" >> "$(dirname "$0")/calls.txt"
"""


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
  answers = "\n".join(
    f"    {axis}) echo {' '.join(names)};;" for axis, names in grid.lists().items()
  )
  softbench.write_text(_RECORDING_SOFTBENCH.format(answers=answers))
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
  axes = grid.lists()
  assert set(axes["agents"]) == set(agents.AGENTS)
  runs = [call for call in calls if "--task" in call]
  assert len(runs) == len(axes["robots"]) * len(axes["tasks"]) * len(agents.AGENTS)
  assert {call.split("--robot ")[1].split()[0] for call in runs} == set(axes["robots"])
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


@pytest.mark.parametrize("axis", list(grid.lists()))
def test_the_cli_prints_each_axis_of_the_grid(axis, capsys):
  assert cli.main(["leaderboard", "--grid", axis]) == 0
  assert capsys.readouterr().out.split() == list(grid.lists()[axis])
