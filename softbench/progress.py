"""Progress bars of long work: what is done of how much, and the time spent (rich)."""

from rich import progress as rich_progress


def counting(
  show: bool = True, transient: bool = False, extra: tuple[rich_progress.ProgressColumn, ...] = ()
) -> rich_progress.Progress:
  """A progress display whose bars read ``description [bar] done/total [extra] elapsed``;
  nothing at all unless ``show``; gone once finished if ``transient``."""
  return rich_progress.Progress(
    rich_progress.TextColumn("{task.description}"),
    rich_progress.BarColumn(),
    rich_progress.MofNCompleteColumn(),
    *extra,
    rich_progress.TimeElapsedColumn(),
    disable=not show,
    transient=transient,
  )
