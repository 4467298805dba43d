"""Runs seeds in worker processes: one per core by default, one torch thread each, with one
progress bar; Ctrl-C or ``kill`` stops the workers with their parent, a parent killed outright
(``kill -9``) takes them with it, and a worker that dies ends the run with a one-line error (the
finished seeds' checkpoints and episodes are reused by the next run)."""

from collections.abc import Iterator
from concurrent import futures
import multiprocessing
import os
import signal
import threading

import torch

from smpl import fitting
from softbench import progress as progress_bars
from softbench import terminal
from softbench.data import dataset

_POLL_SECONDS = 0.2  # (s) How often the parent looks at its worker processes.
ORPHANED_EXIT_CODE = 137  # A worker's exit status once its parent is gone: 128 + SIGKILL's 9.


def _init_worker(states) -> None:
  """Worker initialiser: one torch thread (the workers fill the cores; torch's default, one thread
  per core in every worker, made a BiLSTM's evaluation step 450 times slower, 930 ms against 2 ms,
  with the cores busy); Ctrl-C reaches the parent only, which stops the workers itself, and the
  worker ends with its parent (``_exit_with_parent``); warnings print as in the parent; progress
  bars send their states to the parent's ``states`` queue."""
  torch.set_num_threads(fitting.CPU_THREADS)
  signal.signal(signal.SIGINT, signal.SIG_IGN)
  _exit_with_parent()
  terminal.one_line_warnings()
  progress_bars.relay_to(states)


def _exit_with_parent() -> None:
  """Ends this worker process at once when its parent process ends, from a thread that waits
  for it. A parent killed outright (``kill -9``) cannot terminate its workers: they went on
  training (and writing checkpoints), then waited for work forever, and the fork server and the
  resource tracker, which live as long as a worker, with them (8.6 min and more, measured)."""
  parent = multiprocessing.parent_process()
  if parent is not None:
    threading.Thread(
      target=_exit_after, args=(parent,), name="exit-with-parent", daemon=True
    ).start()


def _exit_after(parent: multiprocessing.process.BaseProcess) -> None:
  """Waits for ``parent`` to end (its sentinel, a pipe whose other end only the parent holds),
  then ends this process without clean-up: the work it was doing has no one to report to."""
  parent.join()
  os._exit(ORPHANED_EXIT_CODE)


def _received(states) -> Iterator[tuple]:
  """The states on the ``states`` queue now, in the order they were put."""
  while not states.empty():
    yield states.get()


class WorkerDied(RuntimeError):
  """A worker process ended without a result; the message says how (signal or exit code)."""


# What a worker's death by a signal most likely means (the kernel's OOM killer sends SIGKILL).
_SIGNAL_CAUSES = {
  signal.SIGKILL: "killed, or out of memory",
  signal.SIGSEGV: "a crash in native code; docs/install.md",
  signal.SIGBUS: "a crash in native code, or a full /dev/shm",
  signal.SIGABRT: "aborted by native code",
}


_AFTERMATH = (-signal.SIGTERM, 255)
"""Exit codes of workers that end because another broke the pool: the pool terminates the others
(SIGTERM), and in the full suite a second worker was seen to end with 255 beside one that exited
with 3 (2026-12-06; its cause not traced)."""


def how_workers_ended(executor: futures.ProcessPoolExecutor) -> str:
  """How the worker that broke ``executor`` ended: 'was killed by SIGSEGV (...)', 'exited with
  code 3'; a worker that ended in the aftermath (``_AFTERMATH``) only where no other did."""
  codes = [process.exitcode for process in (executor._processes or {}).values() if process.exitcode]
  code = next((code for code in codes if code not in _AFTERMATH), codes[0] if codes else None)
  if code is None:
    return "ended without a result"
  if code > 0:
    return f"exited with code {code}"
  killer = signal.Signals(-code)
  cause = _SIGNAL_CAUSES.get(killer)
  return f"was killed by {killer.name}" + (f" ({cause})" if cause else "")


def in_processes(function, arguments: list[tuple], label: str, workers: int) -> list:
  """``function(*args)`` for each entry of ``arguments`` in ``workers`` processes (one torch and
  MuJoCo thread each), with a progress bar of the entries done and one per worker of the work it
  is on (its own bars, relayed), each with the time left at its pace; results in order.

  A worker's exception is raised here. On Ctrl-C, or when a worker dies, the workers are
  terminated; seeds whose checkpoints were written are reused by the next run.

  Raises:
    WorkerDied: a worker process ended without a result.
  """
  progress, worker_bars = progress_bars.counting(extra=progress_bars.time_left()), {}
  # Workers fork from one server process, which imported this module (torch, softbench's data)
  # and ``function``'s once, rather than each importing them as spawned ones did: 3 to 4 s of a
  # core per worker on a 2-core AMD EPYC, 0.2 s for a pool's workers once the server runs. The
  # server lives as long as this process and imports what its first pool named.
  context = multiprocessing.get_context("forkserver")
  context.set_forkserver_preload([__name__, function.__module__])
  states = context.SimpleQueue()  # Written at once (no feeder thread): read before the results.
  executor = futures.ProcessPoolExecutor(
    workers, context, initializer=_init_worker, initargs=(states,)
  )
  try:
    with progress:
      bar = progress.add_task(f"{label} ({workers} processes)", total=len(arguments))
      pending = [executor.submit(function, *entry) for entry in arguments]
      while futures.wait(pending, _POLL_SECONDS, futures.FIRST_EXCEPTION).not_done:
        progress_bars.show_relayed(_received(states), progress, worker_bars)
        progress.update(bar, completed=sum(future.done() for future in pending))
        if any(future.done() and future.exception() for future in pending):
          break
      progress_bars.show_relayed(_received(states), progress, worker_bars)
      outcomes = [future.result() for future in pending]  # Re-raises a worker's error.
      progress.update(bar, completed=len(arguments))
  except futures.process.BrokenProcessPool:
    how = how_workers_ended(executor)
    _terminate(executor)
    raise WorkerDied(
      f"a worker process of {label} {how}; run the same command again to resume"
    ) from None
  except BaseException:  # A worker's error, or Ctrl-C: the other workers stop at once.
    _terminate(executor)
    raise
  # Idle workers exit on their own, so that their clean-up runs (terminating them would leak
  # the semaphores of torch.compile's worker pools).
  executor.shutdown(wait=True)
  return outcomes


def _terminate(executor: futures.ProcessPoolExecutor) -> None:
  """Stops the executor's workers, busy or not, and waits for them."""
  for process in multiprocessing.active_children():  # The executor's workers.
    process.terminate()
  executor.shutdown(wait=True, cancel_futures=True)


def over_seeds(
  function, seeds: int, arguments: tuple, label: str, show_progress: bool, workers: int | None
) -> list:
  """``function(seed, *arguments, show)`` for seeds 0..seeds-1, in ``workers`` processes (default:
  one per core), never more than there are seeds; each seed computes with
  ``smpl.fitting.CPU_THREADS`` torch threads, in this process or a worker."""
  if workers is not None:
    dataset.check_count("workers", workers)
  workers = min(seeds, workers or os.cpu_count() or 1)
  if workers > 1:
    return in_processes(
      function, [(seed, *arguments, False) for seed in range(seeds)], f"{label}: seeds", workers
    )
  with fitting.limited_cpu_threads(fitting.CPU_THREADS, torch.device("cpu")):
    return [function(seed, *arguments, show_progress) for seed in range(seeds)]
