"""``softbench sweep``: a grid of settings (robots x tasks x agents x eval modes, one profile),
and Exp1S on tendon families, run as Ray tasks, on this machine or a Ray cluster, with one record
per setting as ``softbench run`` writes it.

The work is a graph (``grid``): each babbling dataset, forward model and agent is built once for
the whole grid and shared by the evaluations that need it; a setting that has a record of its
profile already is skipped. Tasks run on Ray (``execution``, ``cluster``), exchange their cache
files through Ray's object store (``shipping``), and show one progress display (``display``).
Ctrl-C cancels the tasks and leaves what a rerun resumes from: the records written, the kept
episodes, and the data home's datasets, checkpoints and training snapshots. docs/sweep.md says
how to run one on a cluster.
"""

from collections.abc import Iterator
from collections.abc import Sequence
import contextlib
import dataclasses
import os
import pathlib
import sys

from softbench import profiles
from softbench import storage
from softbench import terminal
from softbench.sweep.grid import Grid
from softbench.sweep.grid import plan


class SweepFailed(RuntimeError):
  """Some settings of a sweep failed; the others' records are written."""


@dataclasses.dataclass(frozen=True)
class SweepResult:
  """The records a sweep wrote (in the order it wrote them) and those it found and skipped."""

  written: tuple[pathlib.Path, ...]
  skipped: tuple[pathlib.Path, ...]


@contextlib.contextmanager
def _data_home(path: str | os.PathLike | None) -> Iterator[None]:
  """Within the block, the data home is ``path`` (absolute), if given, for this process and the
  sweep's workers (``cluster.runtime_env``)."""
  if path is None:
    yield
    return
  before = os.environ.get(storage.HOME_VARIABLE)
  os.environ[storage.HOME_VARIABLE] = str(pathlib.Path(path).expanduser().absolute())
  try:
    yield
  finally:
    if before is None:
      del os.environ[storage.HOME_VARIABLE]
    else:
      os.environ[storage.HOME_VARIABLE] = before


def sweep(
  robots: Sequence[str],
  tasks: Sequence[str],
  agents: Sequence[str],
  results: str | os.PathLike,
  profile: str = profiles.DEFAULT_PROFILE,
  seeds: int | None = None,
  eval_modes: Sequence[str] = ("physics",),
  address: str | None = None,
  data_home: str | os.PathLike | None = None,
  show_progress: bool = True,
  families: Sequence[str] = (),
  dry_run: bool = False,
  streams: Sequence[str] = (),
  strategies: Sequence[str] = (),
) -> SweepResult:
  """Runs every setting of the grid that ``results`` has no record of, as Ray tasks: on the
  cluster at ``address`` (``HOST:PORT``), else on a local Ray with one worker per core (or the
  Ray this process already started); ``data_home`` replaces ``$SOFTBENCH_HOME`` for the driver
  and every worker (docs/sweep.md: what to share). ``families``: also Exp1S on each of these
  tendon families (``softbench run --protocol exp1s --family F``); with ``streams``, each of
  ``strategies`` on each stream and family instead (``softbench run --protocol continual``);
  with either, the robots, tasks and agents may all be empty. ``dry_run``: print what would run
  and build (``Plan.report``) and run nothing (zoo checkpoints the grid needs are taken, as a
  sweep would).

  Raises:
    ValueError: an unknown robot, task, agent, family, profile or eval mode, seeds < 1, an
      empty list, a data home or results folder that cannot be written, or a Ray node with other
      source (one line; all but the last before Ray starts).
    SweepFailed: some settings failed (one line); the others' records are written.
    KeyboardInterrupt: Ctrl-C or ``kill``; a rerun resumes.
  """
  grid = Grid(
    tuple(robots),
    tuple(tasks),
    tuple(agents),
    profile,
    seeds,
    tuple(eval_modes),
    tuple(families),
    tuple(streams),
    tuple(strategies),
  )
  with _data_home(data_home):
    storage.check_home()
    folder = storage.check_writable(results, "results folder", folder=True)
    work = plan(grid, folder)
    if dry_run:
      print(work.report())
      return SweepResult((), work.skipped)
    if work.skipped:
      print(f"sweep: {len(work.skipped)} settings have records already, skipped", file=sys.stderr)
    if work.resumed:
      print(f"sweep: resuming from {len(work.resumed)} finished seeds", file=sys.stderr)
    written, failures = [], {}
    if work.settings:
      # Ray is imported here, not with softbench.sweep, which the command line imports.
      from softbench.sweep import cluster  # pylint: disable=import-outside-toplevel
      from softbench.sweep import execution  # pylint: disable=import-outside-toplevel

      # After Ray starts: its own handler of SIGTERM, which ray.init installs, aborts the process.
      with cluster.connected(address), terminal.sigterm_as_interrupt():
        written, failures = execution.execute(work, folder, show_progress)
  if failures:
    raise SweepFailed(
      f"{len(failures)} of {len(work.settings)} settings failed, their records not written "
      f"(run the same command again to retry them): "
      + "; ".join(f"{name}: {message}" for name, message in failures.items())
    )
  return SweepResult(tuple(written), work.skipped)


__all__ = ["Grid", "SweepFailed", "SweepResult", "sweep"]
