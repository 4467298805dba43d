"""Fixtures shared by the test files."""

import pytest

from softbench import data
from softbench import leaderboard


@pytest.fixture
def assert_regenerates_identically():
  """Checks that the pages of a results folder come out byte-identical when written again and
  when the folder (its records written in another order) is moved elsewhere."""
  def check(results, tmp_path):
    first = leaderboard.write(leaderboard.build(results), results, tmp_path / "site")
    contents = [path.read_bytes() for path in first]
    leaderboard.write(leaderboard.build(results), results, tmp_path / "site")
    assert [path.read_bytes() for path in first] == contents
    moved = tmp_path / "elsewhere"
    (moved / "results").mkdir(parents=True)
    for path in sorted(results.glob("*.json"), reverse=True):
      (moved / "results" / path.name).write_bytes(path.read_bytes())
    again = leaderboard.write(leaderboard.build(moved / "results"), moved / "results",
                              moved / "site")
    assert [path.read_bytes() for path in again] == contents

  return check


@pytest.fixture
def assert_one_line_retraining():
  """Checks that caught warnings hold one ``data.CorruptFileWarning``: one line naming the damaged
  file and saying that it is trained again."""
  def check(caught, path):
    (warning,) = [entry for entry in caught if issubclass(entry.category, data.CorruptFileWarning)]
    message = str(warning.message)
    assert str(path) in message and "training it again" in message and "\n" not in message

  return check
