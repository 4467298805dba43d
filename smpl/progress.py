"""A rich progress bar for `smpl.training.fit`, passed as its `on_epoch_end` callback."""

from __future__ import annotations

from types import TracebackType

from rich.console import Console
from rich.progress import BarColumn
from rich.progress import MofNCompleteColumn
from rich.progress import Progress
from rich.progress import TextColumn
from rich.progress import TimeElapsedColumn

from smpl.training import EpochReport


class EpochProgressBar:
  """Shows epochs done, the latest losses and the best validation loss.

  with EpochProgressBar("column 2", config.max_epochs) as progress:
      train_inverse_model(..., on_epoch_end=progress)
  """

  def __init__(self, description: str, max_epochs: int, console: Console | None = None) -> None:
    self._description = description
    self._progress = Progress(
      TextColumn("{task.description}"),
      BarColumn(),
      MofNCompleteColumn(),
      TextColumn("{task.fields[losses]}"),
      TimeElapsedColumn(),
      console=console,
    )
    self._task = self._progress.add_task(description, total=max_epochs, losses="")

  def __enter__(self) -> EpochProgressBar:
    self._progress.start()
    return self

  def __exit__(
    self,
    exception_type: type[BaseException] | None,
    exception: BaseException | None,
    traceback: TracebackType | None,
  ) -> None:
    self._progress.stop()

  def __call__(self, report: EpochReport) -> None:
    self._progress.update(
      self._task,
      completed=report.epoch + 1,
      losses=(
        f"train {report.train_loss:.2e}  validation {report.validation_loss:.2e}  "
        f"best {report.best_validation_loss:.2e}"
      ),
    )
