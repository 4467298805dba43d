"""``make leaderboard``: one sweep over the grid and Exp1S on every tendon family (the sweep skips
the settings that have a record: test_sweep), then the pages."""

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


def test_the_fill_sweeps_every_agent_on_every_task_and_exp1s_then_the_pages(checkout):
  calls = _fill(checkout)
  axes = grid.lists()
  assert set(axes["agents"]) == set(agents.AGENTS)
  assert set(axes["families"]) == set(robots.TENDON_FAMILY_NAMES)
  assert calls == [
    f"sweep --robots {' '.join(axes['robots'])} --tasks {' '.join(axes['tasks'])} "
    f"--agents {' '.join(axes['agents'])} --protocol exp1s --families "
    f"{' '.join(axes['families'])} --profile paper --results leaderboard/results",
    "leaderboard --results leaderboard/results --write",
  ]


def test_the_fill_sweeps_on_a_cluster_when_given_its_address(checkout):
  subprocess.run(
    ["make", "--no-print-directory", "leaderboard", "ADDRESS=10.0.0.1:6379"],
    cwd=checkout,
    check=True,
    capture_output=True,
    timeout=60,
  )
  calls = (checkout / ".venv" / "bin" / "calls.txt").read_text().splitlines()
  assert "--address 10.0.0.1:6379" in calls[0] and calls[0].startswith("sweep")


@pytest.mark.parametrize("axis", list(grid.lists()))
def test_the_cli_prints_each_axis_of_the_grid(axis, capsys):
  assert cli.main(["leaderboard", "--grid", axis]) == 0
  assert capsys.readouterr().out.split() == list(grid.lists()[axis])
