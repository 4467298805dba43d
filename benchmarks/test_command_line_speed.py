"""Start-up time of the command line (pytest-benchmark; run with `make bench`): a fresh `softbench`
process to its exit, through the console script's launcher as a user starts it.

Goal: `softbench --help`, every command's `--help` and the listings in about a second (each
command imports only its own modules; with every command's imported, `--help` took 6.2 s on 2
cores of an AMD EPYC; `run --help` 4.9 s while it loaded torch).
"""

import subprocess
import sys

import pytest

_ROUNDS = 3  # Fresh processes per command; the first also warms the file cache.
_COMMANDS = (
  ["--help"],
  ["robots"],
  ["tasks"],
  ["leaderboard", "--grid", "agents"],
  ["run", "--help"],
  ["sweep", "--help"],
  ["zoo", "list"],
)


@pytest.mark.parametrize("argv", _COMMANDS, ids=" ".join)
def test_command_start_up_seconds(benchmark, argv):
  command = [sys.executable, "-m", "softbench.launcher", *argv]
  benchmark.pedantic(
    subprocess.run, args=(command,), kwargs={"capture_output": True, "check": True}, rounds=_ROUNDS
  )
