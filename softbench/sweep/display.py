"""One progress display for a whole sweep: its tasks done of all, running, failed, the records
written, the time spent and an estimate of the time left (rich)."""

from rich import progress as rich_progress

from softbench import progress as progress_bars


class Display:
  """A context manager showing one bar over a sweep's Ray tasks (``update`` moves it).

  Running counts the tasks whose inputs are ready, up to the cluster's cores (Ray runs those);
  the time left is rich's estimate from the pace of the tasks so far, which mixes short
  evaluations with long trainings."""

  def __init__(self, tasks: int, settings: int, show: bool):
    self._progress = progress_bars.counting(
      show,
      extra=(
        rich_progress.TextColumn("{task.fields[running]} running, {task.fields[failed]} failed,"),
        rich_progress.TextColumn("{task.fields[records]}/{task.fields[settings]} records,"),
        rich_progress.TimeRemainingColumn(),
        rich_progress.TextColumn("left,"),
      ),
    )
    self._bar = self._progress.add_task(
      "sweep: tasks", total=tasks, running=0, failed=0, records=0, settings=settings
    )

  def __enter__(self) -> "Display":
    self._progress.__enter__()
    return self

  def __exit__(self, *exception) -> None:
    self._progress.__exit__(*exception)

  def update(self, done: int, running: int, failed: int, records: int) -> None:
    self._progress.update(
      self._bar, completed=done, running=running, failed=failed, records=records
    )
