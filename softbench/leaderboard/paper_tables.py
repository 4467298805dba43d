"""The paper's result tables that ship beside the leaderboard's code, as JSON in this package."""

import functools
import importlib.resources
import json


@functools.cache
def load(file_name: str) -> dict:
  """The parsed JSON file ``file_name`` of this package (read once per process)."""
  text = importlib.resources.files(__package__).joinpath(file_name).read_text(encoding="utf-8")
  return json.loads(text)
