"""One progress display for a whole sweep: its tasks done of all, running, failed, the records
written, the time spent and an estimate of the time left (rich); under it, a bar per worker
process of the work it is on (a training's epochs, an episode's steps), relayed from the workers
(``progress.relay_to``)."""

from collections.abc import Iterable

from rich import progress as rich_progress

from softbench import progress as progress_bars


class Display:
  """A context manager showing one bar over a sweep's Ray tasks (``update`` moves it) and the
  workers' bars (``show_workers``).

  Running counts the tasks whose inputs are ready, up to the cluster's cores (Ray runs those);
  the time left is estimated from the pace of the tasks so far (from the first one's end up to
  now, at most ``progress.PACE_WINDOW_S``), which mixes short evaluations with long trainings; a
  worker's bar estimates its own work's the same way."""

  def __init__(self, tasks: int, settings: int, show: bool):
    self._progress = progress_bars.counting(
      show,
      extra=(rich_progress.TextColumn("{task.fields[counts]}"), *progress_bars.time_left()),
    )
    self._settings = settings
    self._bar = self._progress.add_task("sweep: tasks", total=tasks, counts=self._counts(0, 0, 0))
    self._worker_bars = {}

  def __enter__(self) -> "Display":
    self._progress.__enter__()
    return self

  def __exit__(self, *exception) -> None:
    self._progress.__exit__(*exception)

  def _counts(self, running: int, failed: int, records: int) -> str:
    return f"{running} running, {failed} failed, {records}/{self._settings} records,"

  def update(self, done: int, running: int, failed: int, records: int) -> None:
    self._progress.update(self._bar, completed=done, counts=self._counts(running, failed, records))

  def show_workers(self, states: Iterable[tuple]) -> None:
    """Shows the ``states`` that the workers' bars sent, in order (a bar per worker process)."""
    progress_bars.show_relayed(states, self._progress, self._worker_bars, counts="")
