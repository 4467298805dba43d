"""Processes as Linux's /proc shows them, for tests of what outlives a killed parent."""

import contextlib
import os
import pathlib
import signal
import time

PROC = pathlib.Path("/proc")


def _stat_fields(pid: int) -> list[str]:
  """The fields of ``/proc/PID/stat`` after the command's name: state, parent, ..."""
  return (PROC / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()


def descendants(pid: int) -> set[int]:
  """The processes under ``pid`` (children while their parent lives: take them before)."""
  parents = {}
  for entry in PROC.iterdir():
    with contextlib.suppress(OSError, ValueError, IndexError):  # Gone meanwhile, or no process.
      parents[int(entry.name)] = int(_stat_fields(int(entry.name))[1])
  found, frontier = set(), {pid}
  while frontier:
    frontier = {child for child, parent in parents.items() if parent in frontier} - found
    found |= frontier
  return found


def running(pid: int) -> bool:
  """Whether ``pid`` runs (a zombie, ended but not yet reaped, does not)."""
  try:
    return _stat_fields(pid)[0] != "Z"
  except OSError:
    return False


def still_running(pids: set[int], seconds: float) -> list[int]:
  """Those of ``pids`` that run ``seconds`` later (asked sooner, once none runs)."""
  deadline = time.monotonic() + seconds
  while time.monotonic() < deadline and any(running(pid) for pid in pids):
    time.sleep(0.1)
  return sorted(pid for pid in pids if running(pid))


def kill(pids: set[int]) -> None:
  """Kills ``pids`` (what a failed test would otherwise leave running)."""
  for pid in pids:
    with contextlib.suppress(OSError):
      os.kill(pid, signal.SIGKILL)
