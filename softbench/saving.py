"""The one save path of every runner's result.

A runner (``softbench.run``, ``softbench.continual``, ``softbench.retrain``) returns a record from
its ``execute`` and offers ``table(record)`` and ``record_path(record, results)``; ``save`` prints
the table, writes the record (checked, sealed and atomic, never over another record:
``records.write_new``) under the results folder and to an extra copy if asked, and says where.
What only one runner does afterwards (its plots, a video, discarding the finished seeds it kept
for resuming) follows, once the record is safe.
"""

import os
import pathlib
from typing import Protocol

from softbench import records


class Runner(Protocol):
  """What ``save`` needs of a runner module."""

  def table(self, record: dict) -> str: ...

  def record_path(self, record: dict, results: pathlib.Path) -> pathlib.Path: ...


def save(
  runner: Runner, record: dict, results: pathlib.Path, copy: pathlib.Path | None = None
) -> list[pathlib.Path]:
  """Prints ``runner``'s table of ``record``, writes it under ``results`` (and to ``copy``);
  returns the files written, the results folder's first."""
  print(runner.table(record))
  path = records.write_new(record, runner.record_path(record, results))
  print(f"result record: {path}")
  if copy is not None:
    records.write(record, copy)
  return [path] + ([copy] if copy is not None else [])


def link_video(record: dict, files: list[pathlib.Path], video: pathlib.Path) -> None:
  """Rewrites each of ``files`` (copies of ``record``) with a link to ``video``, relative to
  that file."""
  for path in files:
    record["video"] = os.path.relpath(video.resolve(), path.parent.resolve())
    records.write(record, path)
