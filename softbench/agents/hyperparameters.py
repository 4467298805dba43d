"""Each learned agent's hyperparameters: what tuning may change, and the values in use.

Each learned agent's registry entry declares, as data, its tuned parameters and their ranges
(``Learner.search_space``, ``softbench.agents.learners``; ``softbench tune`` searches them with
Optuna, ``softbench.tuning``). The values in use are committed in ``hyperparameters.json`` beside
this file:

  {"default_robot": "tendon-3",
   "agents": {agent: {robot: {"params": {name: value}, "study": summary or null}}}}

An agent on a robot without an entry of its own uses the default robot's values; an agent
without any trains with its model's and optimiser's defaults (a new baseline needs no entry).
``study`` is the summary of the Optuna study that chose the values (null: not chosen by a study).
``values`` reads the file, ``adopt`` writes a study's choice into it. Parameters named in
``softbench.learning.inverse.TRAINING_PARAMETERS`` go to the inverse model's optimiser
(``smpl.training.InverseTrainingConfig``), the others to the agent's model factory as keyword
arguments (``smpl.baselines``). SMPL's width and depth stay at the paper's 2 LSTM layers of 32
units per column (SPEC 5): only its optimisation is tuned.
"""

from collections.abc import Mapping
import json
import pathlib

from softbench import agents
from softbench import robots
from softbench import storage

PATH = pathlib.Path(__file__).with_name("hyperparameters.json")


def search_space(agent: str) -> Mapping:
  """The tuned parameters of learned agent ``agent`` and their ranges (its registry entry's
  ``Learner.search_space``)."""
  learner = agents.learner(agent) if agent in agents.AGENTS else None
  if learner is None:
    raise ValueError(
      f"agent {agent!r} has no hyperparameters to tune; learned agents: "
      f"{', '.join(agents.babbling_learners())}"
    )
  return learner.search_space


def describe_space(agent: str) -> dict[str, str]:
  return {name: distribution.describe() for name, distribution in search_space(agent).items()}


def check_params(agent: str, params: dict) -> dict:
  """``params`` if it sets exactly the agent's tuned parameters, each inside its range.

  Raises:
    ValueError: a missing, unknown or out-of-range parameter (one line).
  """
  space = search_space(agent)
  if not isinstance(params, dict) or set(params) != set(space):
    names = sorted(params) if isinstance(params, dict) else params
    raise ValueError(f"{agent}: hyperparameters must be {', '.join(sorted(space))}, got {names}")
  for name, value in params.items():
    if not space[name].contains(value):
      raise ValueError(
        f"{agent}: {name} = {value!r} is outside its range ({space[name].describe()})"
      )
  return params


def load(path: pathlib.Path | None = None) -> dict:
  """The committed table (``PATH`` unless ``path``), checked: every entry sets exactly its agent's
  tuned parameters, each within its range."""
  path = PATH if path is None else path
  try:
    table = json.loads(pathlib.Path(path).read_text())
  except (OSError, json.JSONDecodeError) as error:
    raise ValueError(f"{path}: not a readable hyperparameters file ({error})") from None
  if not isinstance(table, dict) or set(table) != {"default_robot", "agents"}:
    raise ValueError(f"{path}: expected the keys default_robot and agents")
  default_robot = table["default_robot"]
  robots.make(default_robot)  # An unknown robot raises its own one-line ValueError.
  for agent, entries in table["agents"].items():
    for robot, entry in entries.items():
      if set(entry) != {"params", "study"}:
        raise ValueError(f"{path}: {agent} on {robot}: expected the keys params and study")
      check_params(agent, entry["params"])
  return table


def entry(agent: str, robot: str, path: pathlib.Path | None = None) -> dict:
  """``{"params": ..., "study": ...}`` of ``agent`` on ``robot`` (or on the default robot)."""
  search_space(agent)
  table = load(path)
  entries = table["agents"].get(agent, {})
  return entries.get(robot) or entries.get(table["default_robot"]) or {"params": {}, "study": None}


def values(agent: str, robot: str, path: pathlib.Path | None = None) -> dict:
  """The hyperparameters ``agent`` trains with on ``robot`` (module docstring)."""
  return dict(entry(agent, robot, path)["params"])


def adopt(
  agent: str, robot: str, params: dict, study: dict, path: pathlib.Path | None = None
) -> None:
  """Commits ``params`` (chosen by ``study``) as ``agent``'s values on ``robot``, atomically."""
  path = PATH if path is None else path
  table = load(path)
  check_params(agent, params)
  table["agents"].setdefault(agent, {})[robot] = {"params": dict(params), "study": study}
  storage.write_atomically(path, json.dumps(table, indent=2, allow_nan=False) + "\n")


def loss_text(value: float | None) -> str:
  """A validation MSE as reports show it; None is a loss that was not finite."""
  return "not finite" if value is None else f"{value:.4g}"


def describe_entry(entry: dict) -> str:
  """An ``entry``'s values and where they come from, in one line: ``learning_rate 0.001, ...
  (best of 10 trials on the default profile: validation MSE ...)`` or ``(... not tuned)``."""
  study = entry["study"]
  origin = "not tuned"
  if study is not None:
    origin = (
      f"best of {sum(study['trials'].values())} trials on the {study['profile']} profile: "
      f"validation MSE {loss_text(study['best']['value'])} after {study['trial_epochs']} epochs"
    )
    if "full_budget" in study:
      origin += f", {loss_text(study['full_budget']['best'])} after {study['max_epochs']}"
  settings = ", ".join(f"{name} {value:g}" for name, value in entry["params"].items())
  return f"{settings} ({origin})"
