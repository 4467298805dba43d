"""Which record of a setting the leaderboard shows: the newest (by date, then file name); the
older ones are kept as superseded."""

import datetime


def _newest_first(entry) -> tuple:
  return datetime.datetime.fromisoformat(entry.record["date"]), entry.path.name


def newest_per_setting(entries: list) -> tuple[list, list]:
  """The newest of the ``entries`` (each with ``record``, ``path`` and ``setting``) of each
  setting, and the older ones, newest first: (shown, superseded)."""
  newest, superseded = {}, []
  for entry in sorted(entries, key=_newest_first, reverse=True):
    if entry.setting in newest:
      superseded.append(entry)
    else:
      newest[entry.setting] = entry
  return list(newest.values()), superseded
