"""A progress bar of samples collected (a babbling collection's, a SAC training's environment
steps): done / total, samples per second, time left, time spent; relayed to the parent where it is
hidden in a seed or sweep worker, like every bar of ``softbench.progress``."""

from rich import console as rich_console
from rich import progress as rich_progress
from rich import text

from softbench import progress


class _RateColumn(rich_progress.ProgressColumn):
  """Samples per second, averaged over the last ``progress.PACE_WINDOW_S`` (or rich's last 1,000
  updates)."""

  def render(self, task: rich_progress.Task) -> text.Text:
    speed = task.finished_speed or task.speed
    return text.Text("? samples/s," if speed is None else f"{speed:.1f} samples/s,")


class SampleProgress:
  """A progress bar on stderr; where ``enabled`` is False, none, but its states still go to the
  parent from a seed or sweep worker (``progress.relay_to``). ``completed``: where a resumed
  collection or training starts (not counted in its pace).

  with SampleProgress("tendon-3", total=14000) as bar:
    bar.update(completed)
  """

  def __init__(self, description: str, total: int, completed: int = 0, enabled: bool = True):
    self._progress = progress.counting(
      enabled,
      extra=(_RateColumn(), *progress.time_left()),
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
