"""Seeds in worker processes (``softbench.runners.run``): results in order, errors raised, a dead
worker reported instead of a hang, Ctrl-C or kill stopping every worker."""

import multiprocessing
import os
import select
import signal
import subprocess
import sys
import time

import process_tree
import pytest
import torch

from softbench import progress
from softbench.runners import parallel_seeds

CHILD_DEADLINE_S = 60  # (s) A child program still running after this has hung.


def square_and_torch_threads(value):
  return value * value, torch.get_num_threads()


def fail(value):
  raise ValueError(f"bad seed {value}")


def die(value):
  os._exit(3)


def crash(value):
  os.kill(os.getpid(), signal.SIGSEGV)


def test_results_come_back_in_order_from_workers_of_one_torch_thread():
  # Torch's default is one thread per core in every worker, which oversubscribes the cores.
  assert parallel_seeds.in_processes(
    square_and_torch_threads, [(3,), (1,), (2,)], "squares", workers=2
  ) == [(9, 1), (1, 1), (4, 1)]
  before = torch.get_num_threads()
  torch.set_num_threads(2)
  try:  # In this process (one worker), for the seeds only.
    assert parallel_seeds.over_seeds(
      lambda seed, show: square_and_torch_threads(seed), 2, (), "threads", False, workers=1
    ) == [(0, 1), (1, 1)]
    assert torch.get_num_threads() == 2
  finally:
    torch.set_num_threads(before)


def count_with_a_hidden_bar(value):
  with progress.counting(show=False) as bars:  # As a seed's training in a worker draws it.
    bar = bars.add_task(f"counting to {value}", total=value)
    for _ in range(value):
      bars.advance(bar)
  return value


def test_each_worker_shows_the_bars_it_does_not_draw_itself(monkeypatch, capsys):
  monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.0)  # Every state a line (not a terminal).
  assert parallel_seeds.in_processes(
    count_with_a_hidden_bar, [(3,), (4,)], "counting", workers=2
  ) == [3, 4]
  lines = capsys.readouterr().out.splitlines()
  for value in (3, 4):  # Its last state, sent when it completed.
    assert any(line.startswith(f"counting to {value}: {value}/{value}, ") for line in lines)


def test_a_worker_error_is_raised():
  with pytest.raises(ValueError, match="bad seed"):
    parallel_seeds.in_processes(fail, [(1,), (2,)], "failing", workers=2)


_DYING_PROGRAM = """
import sys
sys.path.insert(0, {tests!r})
from softbench.runners import parallel_seeds
from softbench import progress
import test_parallel_seeds
for dying in (test_parallel_seeds.die, test_parallel_seeds.crash):
  try:
    parallel_seeds.in_processes(dying, [(1,), (2,)], "dying", workers=2)
  except parallel_seeds.WorkerDied as error:
    print("reported:", error)
"""


def test_a_dead_worker_is_reported_with_how_it_ended_not_waited_for():
  # In a child with a deadline: a hang fails the test (TimeoutExpired) instead of the suite. One
  # child for both deaths: its imports take most of the time.
  program = _DYING_PROGRAM.format(tests=os.path.dirname(__file__))
  result = subprocess.run(
    [sys.executable, "-c", program], capture_output=True, text=True, timeout=CHILD_DEADLINE_S
  )
  assert [line for line in result.stdout.splitlines() if line.startswith("reported:")] == [
    "reported: a worker process of dying exited with code 3; run the same command again to resume",
    "reported: a worker process of dying was killed by SIGSEGV (a crash in native code; "
    "docs/install.md); run the same command again to resume",
  ], result


_INTERRUPTED_PROGRAM = """
import signal, sys, time
# Ctrl-C as in a terminal, even where the test runner was started as a background job of a
# non-interactive shell, which leaves SIGINT ignored in every process it starts.
signal.signal(signal.SIGINT, signal.default_int_handler)
sys.path.insert(0, {tests!r})
from softbench.runners import parallel_seeds
from softbench import progress
from softbench import terminal
import test_parallel_seeds
try:
  with terminal.sigterm_as_interrupt():  # As softbench.cli.main runs every command.
    parallel_seeds.in_processes(test_parallel_seeds.sleep_long, [(0,), (1,)], "sleepers", workers=2)
except KeyboardInterrupt:
  import multiprocessing
  print("children left:", len(multiprocessing.active_children()), flush=True)
"""


def sleep_long(value):
  # One write (print writes the text and the newline apart), so two workers' lines never mix.
  sys.stdout.write("worker started\n")
  sys.stdout.flush()
  time.sleep(600)


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "kill"])
def test_ctrl_c_or_kill_stops_every_worker(stop):
  program = _INTERRUPTED_PROGRAM.format(tests=os.path.dirname(__file__))
  process = subprocess.Popen([sys.executable, "-c", program], stdout=subprocess.PIPE, text=True)
  try:
    started, _, _ = select.select([process.stdout], [], [], CHILD_DEADLINE_S)
    assert started, f"no worker started in {CHILD_DEADLINE_S} s"
    assert process.stdout.readline().strip() == "worker started"
    time.sleep(1.0)
    process.send_signal(stop)
    out, _ = process.communicate(timeout=CHILD_DEADLINE_S)
  finally:
    process.kill()  # A no-op once it has ended.
  assert "children left: 0" in out


_SEMAPHORE_PROGRAM = """
import sys
sys.path.insert(0, {tests!r})
from softbench.runners import parallel_seeds
from softbench import progress
import test_parallel_seeds
print(parallel_seeds.in_processes(test_parallel_seeds.doubled_holding_a_semaphore,
                                  [(1.0,), (2.0,)], "holding", workers=1))
"""
_HELD_SEMAPHORES = []


def doubled_holding_a_semaphore(value):
  """``2 * value``; the worker keeps a named semaphore, as torch.compile's worker pools do."""
  if not _HELD_SEMAPHORES:
    _HELD_SEMAPHORES.append(multiprocessing.get_context("spawn").Semaphore())
  return 2 * value


def test_finished_workers_exit_cleanly():
  # Terminating idle workers left torch.compile's pool semaphores to the resource tracker, which
  # warned "There appear to be 2 leaked semaphore objects" after every compiled training run. One
  # worker (idle once both values are done) that holds a semaphore shows it (terminated, it
  # leaves "1 leaked semaphore objects", measured).
  program = _SEMAPHORE_PROGRAM.format(tests=os.path.dirname(__file__))
  result = subprocess.run(
    [sys.executable, "-c", program], capture_output=True, text=True, timeout=300
  )
  assert result.returncode == 0, result.stderr
  assert result.stdout.strip().endswith("[2.0, 4.0]")
  assert "leaked" not in result.stderr, result.stderr


_KILLED_PROGRAM = """
import sys
sys.path.insert(0, {tests!r})
from softbench.runners import parallel_seeds
import test_parallel_seeds
parallel_seeds.in_processes(test_parallel_seeds.sleep_long, [(0,), (1,)], "sleepers", workers=2)
"""
ORPHANS_DEADLINE_S = 5  # (s) How long a killed parent's workers may outlive it.


@pytest.mark.skipif(not process_tree.PROC.is_dir(), reason="reads Linux's /proc")
def test_a_parent_killed_outright_takes_its_workers_with_it():
  # Before workers watched their parent, kill -9 of a softbench run left the fork server, two
  # workers and the resource tracker running for 8.6 minutes and more.
  program = _KILLED_PROGRAM.format(tests=os.path.dirname(__file__))
  process = subprocess.Popen([sys.executable, "-c", program], stdout=subprocess.PIPE, text=True)
  left = set()
  try:
    for _ in range(2):  # Both workers busy.
      started, _, _ = select.select([process.stdout], [], [], CHILD_DEADLINE_S)
      assert started, f"no worker started in {CHILD_DEADLINE_S} s"
      assert process.stdout.readline().strip() == "worker started"
    left = process_tree.descendants(process.pid)
    assert len(left) >= 3  # The fork server and its two workers, and the resource tracker.
    process.kill()
    process.wait()
    assert not process_tree.still_running(left, ORPHANS_DEADLINE_S)
  finally:
    process.kill()  # A no-op once it has ended.
    process_tree.kill(left)
