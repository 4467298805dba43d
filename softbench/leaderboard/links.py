"""Links from the generated pages to records and videos, relative to the pages' folder.

A record's ``video`` is a URL (kept as it is) or a file path; a relative path is relative to the
record's own folder, so that records and their videos can move together.
"""

import os
import pathlib
import urllib.parse

from softbench.leaderboard import ranking

_URL_SCHEMES = ("http", "https")


def relative(target: pathlib.Path, out: pathlib.Path) -> str:
  """``target``'s path from the folder ``out``, with forward slashes."""
  return pathlib.Path(os.path.relpath(target.resolve(), out.resolve())).as_posix()


def record(entry: ranking.BoardEntry, out: pathlib.Path) -> str:
  """The record file of ``entry``, from the folder ``out``."""
  return relative(entry.path, out)


def video(entry: ranking.BoardEntry, out: pathlib.Path) -> str | None:
  """The video of ``entry`` from the folder ``out``, or ``None`` if the record has none."""
  location = entry.record.get("video")
  if location is None:
    return None
  if urllib.parse.urlparse(location).scheme in _URL_SCHEMES:
    return location
  return relative(entry.path.parent / pathlib.Path(location), out)
