"""Progress bars of long work: what is done of how much, and the time spent (rich).

rich draws no bars on an output that is not a terminal (a log file of a job in the background);
there a bar writes a line of its state instead, at most every ``LOG_INTERVAL_S`` and once more
when the display stops, in place of rich's last frame (cropped to 80 columns there). In a seed
worker (``parallel_seeds``), whose bars are not shown, every bar sends its state to the parent
instead (``relay_to``), which shows a bar per worker. ``epochs`` counts a training's epochs,
``counting`` any work, ``SampleProgress`` samples collected (a babbling collection's, a SAC
training's environment steps)."""

from collections.abc import Iterable
import contextlib
import datetime
import math
import os
import time

from rich import console as rich_console
from rich import progress as rich_progress
from rich.text import Text

LOG_INTERVAL_S = 60.0  # (s) Least time between two lines of one bar written to a log.
RELAY_INTERVAL_S = 0.5  # (s) Least time between two states of one bar sent to the parent.
# (s) How far back a bar's rate and time left look (rich's default: 30 s). A sweep's tasks and a
# SAC training's 1,000-step chunks end minutes apart: over 30 s there was no estimate at all.
PACE_WINDOW_S = 7 * 24 * 3600.0

_relay = None  # Where this process's bars send their states (a seed worker's queue), or None.


def relay_to(queue) -> None:
  """From now on, every bar of this process, shown or not, puts its state on ``queue`` (a
  multiprocessing ``SimpleQueue``, or a sweep's ``sweep.relay.Relay``; None: no longer) as
  ``(process id, description, completed, total)``: at most every ``RELAY_INTERVAL_S`` per bar,
  and when the bar completes."""
  global _relay  # pylint: disable=global-statement
  _relay = queue


def show_relayed(
  states: Iterable[tuple], progress: rich_progress.Progress, bars: dict, **fields
) -> None:
  """Shows on ``progress`` the ``states`` that workers' bars sent (``relay_to``), in order: a bar
  per worker process (kept in ``bars``, with ``fields`` for the display's columns), showing the
  work that worker last reported on, restarted (elapsed time too) when that work changes."""
  for worker, description, completed, total in states:
    if worker not in bars:
      bars[worker] = progress.add_task(description, total=total, **fields), description
    elif bars[worker][1] != description:
      bars[worker] = bars[worker][0], description
      progress.reset(bars[worker][0], total=total, description=description)
    progress.update(bars[worker][0], completed=completed, total=total)


class _Progress(rich_progress.Progress):
  """rich's Progress, with a line per bar at most every ``LOG_INTERVAL_S``, and one at the end
  instead of the last frame (none if transient), where the console is not a terminal."""

  def __init__(
    self,
    *columns: rich_progress.ProgressColumn,
    logged: tuple[rich_progress.ProgressColumn, ...] = (),
    **options,
  ) -> None:
    super().__init__(*columns, **options)
    self._logged_columns = logged
    self._logged_at: dict[rich_progress.TaskID, float] = {}
    self._relayed_at: dict[rich_progress.TaskID, float] = {}
    self._logs = not self.disable and not self.console.is_terminal
    self._ends_with_lines = self._logs and not self.live.transient
    self.live.transient |= self._logs  # In a log, its lines stand for the last frame.

  def stop(self) -> None:
    if not (self._logs and self.live.is_started):
      super().stop()
      return
    for task in self.tasks if self._ends_with_lines else ():
      self._write_line(task)
    self.live.stop()  # Not Progress.stop, whose blank line ends a frame that a log does not get.

  def update(self, task_id: rich_progress.TaskID, **changes) -> None:
    super().update(task_id, **changes)
    self._log(task_id)
    self._relay(task_id)

  def advance(self, task_id: rich_progress.TaskID, advance: float = 1) -> None:
    super().advance(task_id, advance)
    self._log(task_id)
    self._relay(task_id)

  def _relay(self, task_id: rich_progress.TaskID) -> None:
    if _relay is None:
      return
    now = time.monotonic()
    recent = now - self._relayed_at.get(task_id, -RELAY_INTERVAL_S) < RELAY_INTERVAL_S
    (task,) = [task for task in self.tasks if task.id == task_id]
    if recent and not task.finished:
      return
    self._relayed_at[task_id] = now
    _relay.put((os.getpid(), task.description, task.completed, task.total))

  def _log(self, task_id: rich_progress.TaskID) -> None:
    if not self._logs:
      return
    now = time.monotonic()
    if now - self._logged_at.setdefault(task_id, now) < LOG_INTERVAL_S:
      return
    self._logged_at[task_id] = now
    (task,) = [task for task in self.tasks if task.id == task_id]
    self._write_line(task)

  def _write_line(self, task: rich_progress.Task) -> None:
    """The bar's state as one line, however long: description, done/total, extra, elapsed."""
    elapsed = datetime.timedelta(seconds=round(task.elapsed or 0.0))
    total = "?" if task.total is None else f"{task.total:g}"
    texts = (column.render(task).plain for column in self._logged_columns)
    extra = " ".join(text for text in texts if text).rstrip(",")
    extra = f"{extra}, " if extra else ""
    line = f"{task.description}: {task.completed:g}/{total}, {extra}{elapsed} elapsed"
    self.console.print(line, soft_wrap=True)  # One line, however long.


class _TimeLeftColumn(rich_progress.TimeRemainingColumn):
  """rich's time left, at the bar's pace up to now rather than up to its last update: the work
  done since the bar's first update over the time since then. At an update the two agree; while
  nothing ends, this one grows, where rich's keeps what the last update gave (a sweep 46 minutes
  into two long trainings, its first tasks done within seconds, read ``0:01:07 left``)."""

  def render(self, task: rich_progress.Task) -> Text:
    if task.total is None:
      return Text("")
    seconds = _time_left_s(task)
    if seconds is None:
      return Text("-:--:--", style="progress.remaining")
    minutes, seconds = divmod(int(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return Text(f"{hours:d}:{minutes:02d}:{seconds:02d}", style="progress.remaining")


def _time_left_s(task: rich_progress.Task) -> float | None:
  """Seconds left at the pace since the bar's first update (None before a second one); the
  first update's own work counts as done before the pace begins, as in rich's ``Task.speed``."""
  if task.finished:
    return 0.0
  with task._lock:  # pylint: disable=protected-access
    samples = list(task._progress)  # pylint: disable=protected-access
  done = sum(sample.completed for sample in samples[1:])
  seconds = task.get_time() - samples[0].timestamp if samples else 0.0
  if not done or seconds <= 0.0:
    return None
  return math.ceil(task.remaining * seconds / done)


def time_left() -> tuple[rich_progress.ProgressColumn, ...]:
  """Columns for ``counting``'s ``extra``: the time left at the bar's pace from its first update
  up to now, over at most ``PACE_WINDOW_S`` (``-:--:--`` before it has one), read ``1:52:10
  left,``. New ones for each display (a column caches what it drew by task id)."""
  return _TimeLeftColumn(), rich_progress.TextColumn("left,")


class _Epochs:
  """An epoch callback of ``smpl.training`` (a context manager): a bar of the epochs done of the
  budget, the latest losses and the time left (at most: early stopping may end the training
  sooner; a resumed training's pace is that of the epochs run since), complete when the training
  ends; drawn if ``show``, else only relayed (``relay_to``)."""

  def __init__(self, label: str, max_epochs: int, show: bool) -> None:
    self._progress = counting(
      show,
      extra=(rich_progress.TextColumn("{task.fields[losses]}"), *time_left()),
    )
    self._task = self._progress.add_task(label, total=max_epochs, losses="")

  def __enter__(self) -> "_Epochs":
    self._progress.start()
    return self

  def __exit__(self, error_type, *exception) -> None:
    if error_type is None:  # Trained (early stopping included): the bar ends complete.
      (task,) = self._progress.tasks
      self._progress.update(self._task, total=task.completed or 1, completed=task.completed or 1)
    self._progress.stop()

  def __call__(self, report) -> None:
    losses = (
      f"train {report.train_loss:.2e}, validation {report.validation_loss:.2e}, "
      f"best {report.best_validation_loss:.2e},"
    )
    if report.resumed:  # Where a resumed training starts: no pace, nothing relayed yet.
      self._progress.reset(self._task, completed=report.epoch + 1, losses=losses)
    else:
      self._progress.update(self._task, completed=report.epoch + 1, losses=losses)


def epochs(label: str | None, max_epochs: int, show: bool):
  """The epoch progress bar of a training named ``label`` (a context manager giving the callback
  ``smpl.training`` takes, or None): drawn if ``show``, else relayed in a seed or sweep worker
  (``relay_to``); none if ``label`` is None or nothing would show it."""
  if label is None or not (show or _relay is not None):
    return contextlib.nullcontext(None)
  return _Epochs(label, max_epochs, show)


def counting(
  show: bool = True,
  transient: bool = False,
  extra: tuple[rich_progress.ProgressColumn, ...] = (),
  **options,
) -> rich_progress.Progress:
  """A progress display whose bars read ``description [bar] done/total [extra] elapsed``;
  nothing at all unless ``show``; gone once finished if ``transient``; on an output that is not
  a terminal, a line per bar (with the extra columns' text) at most every ``LOG_INTERVAL_S``. A
  time-left column estimates from each bar's pace over its last ``PACE_WINDOW_S``. ``options``:
  rich's other ``Progress`` options (a test's own clock, ``get_time``)."""
  return _Progress(
    rich_progress.TextColumn("{task.description}"),
    rich_progress.BarColumn(),
    rich_progress.MofNCompleteColumn(),
    *extra,
    rich_progress.TimeElapsedColumn(),
    logged=extra,
    disable=not show,
    transient=transient,
    speed_estimate_period=PACE_WINDOW_S,
    **options,
  )


class _RateColumn(rich_progress.ProgressColumn):
  """Samples per second, averaged over the last ``PACE_WINDOW_S`` (or rich's last 1,000
  updates)."""

  def render(self, task: rich_progress.Task) -> Text:
    speed = task.finished_speed or task.speed
    return Text("? samples/s," if speed is None else f"{speed:.1f} samples/s,")


class SampleProgress:
  """A progress bar on stderr; where ``enabled`` is False, none, but its states still go to the
  parent from a seed or sweep worker (``relay_to``). ``completed``: where a resumed
  collection or training starts (not counted in its pace).

  with SampleProgress("tendon-3", total=14000) as bar:
    bar.update(completed)
  """

  def __init__(self, description: str, total: int, completed: int = 0, enabled: bool = True):
    self._progress = counting(
      enabled,
      extra=(_RateColumn(), *time_left()),
      console=rich_console.Console(stderr=True),
    )
    self._task = self._progress.add_task(description, total=total, completed=completed)

  def __enter__(self) -> "SampleProgress":
    self._progress.start()
    return self

  def __exit__(self, *exception) -> None:
    self._progress.stop()

  def update(self, completed: int) -> None:
    self._progress.update(self._task, completed=completed)
