"""Progress bars of long work: what is done of how much, and the time spent (rich).

rich draws no bars on an output that is not a terminal (a log file of a job in the background)
until the work ends; there a bar also writes a line of its state at most every
``LOG_INTERVAL_S``."""

import datetime
import time

from rich import progress as rich_progress

LOG_INTERVAL_S = 60.0  # (s) Least time between two lines of one bar written to a log.


class _Progress(rich_progress.Progress):
  """rich's Progress, with a line per bar at most every ``LOG_INTERVAL_S`` where the console is
  not a terminal."""

  def __init__(self, *columns: rich_progress.ProgressColumn, **options) -> None:
    super().__init__(*columns, **options)
    self._logged_at: dict[rich_progress.TaskID, float] = {}

  def update(self, task_id: rich_progress.TaskID, **changes) -> None:
    super().update(task_id, **changes)
    self._log(task_id)

  def advance(self, task_id: rich_progress.TaskID, advance: float = 1) -> None:
    super().advance(task_id, advance)
    self._log(task_id)

  def _log(self, task_id: rich_progress.TaskID) -> None:
    if self.disable or self.console.is_terminal:
      return
    now = time.monotonic()
    if now - self._logged_at.setdefault(task_id, now) < LOG_INTERVAL_S:
      return
    self._logged_at[task_id] = now
    (task,) = [task for task in self.tasks if task.id == task_id]
    elapsed = datetime.timedelta(seconds=round(task.elapsed or 0.0))
    total = "?" if task.total is None else f"{task.total:g}"
    self.console.print(f"{task.description}: {task.completed:g}/{total}, {elapsed} elapsed")


def counting(
  show: bool = True, transient: bool = False, extra: tuple[rich_progress.ProgressColumn, ...] = ()
) -> rich_progress.Progress:
  """A progress display whose bars read ``description [bar] done/total [extra] elapsed``;
  nothing at all unless ``show``; gone once finished if ``transient``; on an output that is not
  a terminal, a line per bar at most every ``LOG_INTERVAL_S``."""
  return _Progress(
    rich_progress.TextColumn("{task.description}"),
    rich_progress.BarColumn(),
    rich_progress.MofNCompleteColumn(),
    *extra,
    rich_progress.TimeElapsedColumn(),
    disable=not show,
    transient=transient,
  )
