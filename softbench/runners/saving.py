"""The one save path of every runner's result.

A runner (``run``, ``continual``, ``retrain`` of ``softbench.runners``) returns a record from its
``execute`` and offers ``table(record)`` and ``record_path(record, results)``; ``save`` prints the
table, writes the record (checked, sealed and atomic, never over another record:
``records.write_new``) under the results folder (by default the user's own,
``records.user_folder()``) and to an extra copy if asked, and says where and how to rank it. What
only one runner does afterwards (its plots, a video, discarding the finished seeds it kept for
resuming) follows, once the record is safe."""

from collections.abc import Callable
import os
import pathlib
from typing import Protocol

from softbench import records
from softbench import terminal


class Runner(Protocol):
  """What ``save`` needs of a runner module."""

  def table(self, record: dict) -> str: ...

  def record_path(self, record: dict, results: pathlib.Path) -> pathlib.Path: ...


class RunComplete(KeyboardInterrupt):
  """Ctrl-C or ``kill`` once a command's record was written: the run is complete (running it
  again would make a second record), what follows the record (a copy, plots, a video) maybe not."""

  def __init__(self, path: pathlib.Path):
    super().__init__(str(path))
    self.path = path


def save(
  runner: Runner,
  record: dict,
  results: pathlib.Path,
  copy: pathlib.Path | None = None,
  then: Callable[[list[pathlib.Path]], None] | None = None,
  ends_command: bool = True,
) -> list[pathlib.Path]:
  """Prints ``runner``'s table of ``record``, writes it under ``results`` (and to ``copy``), then
  runs ``then(files)`` (its plots, a video); returns the files written, the results folder's
  first. An interrupt during the record's write waits for its end (``terminal.interrupts_held``);
  once the record is written, an interrupt is ``RunComplete`` where the record ``ends_command``
  (not a sweep's, which goes on)."""
  print(runner.table(record))
  path = None
  try:
    with terminal.interrupts_held():
      path = records.write_new(record, runner.record_path(record, results))
    print(f"result record: {path}")
    if pathlib.Path(results).resolve() != records.DEFAULT_FOLDER.resolve():
      print(f"rank your runs: softbench leaderboard --results {results}")
    if copy is not None:
      records.write(record, copy)
    files = [path] + ([copy] if copy is not None else [])
    if then is not None:
      then(files)
  except KeyboardInterrupt:
    if path is None or not ends_command:
      raise
    raise RunComplete(path) from None
  return files


def link_video(record: dict, files: list[pathlib.Path], video: pathlib.Path) -> None:
  """Rewrites each of ``files`` (copies of ``record``) with a link to ``video``, relative to
  that file."""
  for path in files:
    record["video"] = os.path.relpath(video.resolve(), path.parent.resolve())
    records.write(record, path)
