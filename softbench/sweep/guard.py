"""Ends a local Ray's processes with the sweep that started them, however the sweep ends.

Ray kills its head processes when the driver dies, but not the agents the raylet starts: after
``kill -9`` of a sweep, Ray's dashboard and runtime-env agents lived 61 s more (a report to the
dead GCS, with a 60 s timeout). The guard, a small process the driver starts after ``ray.init``
(``start``), follows every descendant of Ray's head processes, and once its stdin ends (a pipe
that only the driver writes: closed at the sweep's end, or by the driver's death) kills those
still running. It reads Linux's /proc; elsewhere no guard starts.

It runs as a script, by its path, and imports nothing of softbench: it starts in a blink.
"""

import contextlib
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

POLL_S = 0.5  # (s) How often the guard looks for processes started since.
READY = b"following\n"  # What the guard writes once it follows the processes there are.
_PROC = pathlib.Path("/proc")


def _parent_and_start(pid: int) -> tuple[int, str] | None:
  """``pid``'s parent and start time (clock ticks after boot: a reused pid has another); None
  where it has ended."""
  try:
    fields = (_PROC / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()
  except (OSError, IndexError):
    return None
  return int(fields[1]), fields[19]


def _processes() -> dict[int, tuple[int, str]]:
  """Every process's parent and start time."""
  found = {}
  for entry in _PROC.iterdir():
    if entry.name.isdigit() and (facts := _parent_and_start(int(entry.name))) is not None:
      found[int(entry.name)] = facts
  return found


def children(pid: int) -> set[int]:
  """The processes whose parent is ``pid``."""
  return {child for child, (parent, _) in _processes().items() if parent == pid}


def _under(roots: dict[int, str]) -> dict[int, str]:
  """``roots`` (pid: start time) still running, and every process under them."""
  table = _processes()
  found = {pid: started for pid, started in roots.items() if table.get(pid, (0, ""))[1] == started}
  frontier = set(found)
  while frontier:
    frontier = {pid for pid, (parent, _) in table.items() if parent in frontier} - set(found)
    found.update({pid: table[pid][1] for pid in frontier})
  return found


def _follow(followed: dict[int, str], lock: threading.Lock) -> None:
  """Adds the processes started under ``followed`` to it, every ``POLL_S``."""
  while True:
    time.sleep(POLL_S)
    with lock:
      snapshot = dict(followed)
    found = _under(snapshot)
    with lock:
      followed.update(found)


def _kill(followed: dict[int, str]) -> None:
  """Kills the processes of ``followed`` that still run (the same process: same start time)."""
  for pid, started in followed.items():
    facts = _parent_and_start(pid)
    if facts is not None and facts[1] == started:
      with contextlib.suppress(OSError):
        os.kill(pid, signal.SIGKILL)


def main(roots: list[int]) -> None:
  """Follows ``roots`` and what they start until stdin ends, then kills what still runs."""
  signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the driver's to handle.
  started = {pid: facts[1] for pid in roots if (facts := _parent_and_start(pid)) is not None}
  followed, lock = _under(started), threading.Lock()
  threading.Thread(target=_follow, args=(followed, lock), daemon=True).start()
  sys.stdout.buffer.write(READY)
  sys.stdout.buffer.flush()
  sys.stdin.buffer.read()  # Until the driver closes the pipe, or ends.
  with lock:
    _kill(dict(followed))


def start(roots: set[int]) -> subprocess.Popen | None:
  """A guard of ``roots`` (pids) and what they start, once it follows them; None without
  /proc. Closing its stdin ends it, killing what still runs."""
  if not roots or not _PROC.is_dir():
    return None
  guard = subprocess.Popen(
    [sys.executable, __file__, *map(str, sorted(roots))],
    stdin=subprocess.PIPE,
    stdout=subprocess.PIPE,
  )
  guard.stdout.readline()  # READY (or nothing, had it failed): it follows them now.
  return guard


def stop(guard: subprocess.Popen | None) -> None:
  """Ends ``guard`` (of ``start``), which kills what it follows that still runs."""
  if guard is not None:
    guard.stdin.close()
    guard.wait()
    guard.stdout.close()


if __name__ == "__main__":
  main([int(pid) for pid in sys.argv[1:]])
