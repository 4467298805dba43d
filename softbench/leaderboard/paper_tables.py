"""The paper's result tables that ship beside the leaderboard's code, as JSON in this package."""

import functools
import importlib.resources
import json

from softbench import robots


@functools.cache
def load(file_name: str) -> dict:
  """The parsed JSON file ``file_name`` of this package (read once per process)."""
  text = importlib.resources.files(__package__).joinpath(file_name).read_text(encoding="utf-8")
  return json.loads(text)


def paper_robot(robot: str) -> str:
  """The name under which the paper's tables hold ``robot``: a tendon arm of any family is the
  paper's arm of as many modules (its tables are keyed ``tendon-N``; the paper's simulator acts
  within each module, like ``tendon-local-N``, and softbench compares both plants with it)."""
  return f"tendon-{robots.num_modules(robot)}" if robots.is_tendon(robot) else robot
