"""Each learned agent's hyperparameters: what tuning may change, and the values in use.

``SEARCH_SPACES`` declares, once and as data, every tuned parameter of every learned agent and its
range (``softbench tune`` searches it with Optuna, ``softbench.tuning``). The values in use are
committed in ``hyperparameters.json`` beside this file:

  {"default_robot": "tendon-3",
   "agents": {agent: {robot: {"params": {name: value}, "study": summary or null}}}}

An agent on a robot without an entry of its own uses the default robot's values. ``study`` is the
summary of the Optuna study that chose the values (null: not chosen by a study). ``values`` reads
the file, ``adopt`` writes a study's choice into it. Parameters named in ``TRAINING_PARAMETERS``
go to the inverse model's optimiser (``smpl.training.InverseTrainingConfig``), the others to the
agent's model factory as keyword arguments (``smpl.baselines``). SMPL's width and depth stay at
the paper's 2 LSTM layers of 32 units per column (SPEC 5): only its optimisation is tuned.
"""

import dataclasses
import json
import numbers
import pathlib

from softbench import robots
from softbench import storage

PATH = pathlib.Path(__file__).with_name("hyperparameters.json")
TRAINING_PARAMETERS = ("learning_rate", "batch_size", "weight_decay")


@dataclasses.dataclass(frozen=True)
class LogUniform:
  """A float drawn log-uniformly from [low, high]."""

  low: float
  high: float

  def suggest(self, trial, name: str) -> float:
    return trial.suggest_float(name, self.low, self.high, log=True)

  def contains(self, value) -> bool:
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and self.low <= value <= self.high)

  def describe(self) -> str:
    return f"log-uniform {self.low:g} .. {self.high:g}"


@dataclasses.dataclass(frozen=True)
class Choice:
  """One of a few values (Optuna's categorical distribution)."""

  values: tuple

  def suggest(self, trial, name: str):
    return trial.suggest_categorical(name, self.values)

  def contains(self, value) -> bool:
    # An integer option takes only an integer (a batch size of 32.0 is refused).
    return (not isinstance(value, bool) and isinstance(value, numbers.Real)
            and any(value == option and (isinstance(value, int) or not isinstance(option, int))
                    for option in self.values))

  def describe(self) -> str:
    return "one of " + ", ".join(f"{value:g}" for value in self.values)


_OPTIMISATION = {
    "learning_rate": LogUniform(1e-4, 1e-2),
    "batch_size": Choice((32, 64, 128)),  # 16 left out: it doubles a trial's time (see README).
    "weight_decay": Choice((0.0, 1e-6, 1e-5, 1e-4)),
}
_RECURRENT = {"hidden_size": Choice((16, 32, 64, 128)), "num_layers": Choice((1, 2, 3))}

SEARCH_SPACES = {
    "smpl": dict(_OPTIMISATION),  # Width and depth fixed by the paper (module docstring).
    "mlp": {**_OPTIMISATION, "hidden_size": Choice((32, 64, 128, 256))},  # 3 layers (paper).
    "lstm": {**_OPTIMISATION, **_RECURRENT},
    "vae-lstm": {**_OPTIMISATION, **_RECURRENT, "latent_size": Choice((2, 4, 8, 16)),
                 "kl_weight": LogUniform(1e-5, 1e-1)},
    "bilstm": {**_OPTIMISATION, **_RECURRENT},
}


def search_space(agent: str) -> dict:
  """The tuned parameters of learned agent ``agent`` and their ranges."""
  if agent not in SEARCH_SPACES:
    raise ValueError(f"agent {agent!r} has no hyperparameters to tune; learned agents: "
                     f"{', '.join(SEARCH_SPACES)}")
  return SEARCH_SPACES[agent]


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
      raise ValueError(f"{agent}: {name} = {value!r} is outside its range "
                       f"({space[name].describe()})")
  return params


def load(path: pathlib.Path | None = None) -> dict:
  """The committed table (``PATH`` unless ``path``), checked: every learned agent has values for
  the default robot."""
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
    if default_robot not in entries:
      raise ValueError(f"{path}: {agent} has no values for the default robot {default_robot}")
    for robot, entry in entries.items():
      if set(entry) != {"params", "study"}:
        raise ValueError(f"{path}: {agent} on {robot}: expected the keys params and study")
      check_params(agent, entry["params"])
  missing = set(SEARCH_SPACES) - set(table["agents"])
  if missing:
    raise ValueError(f"{path}: no hyperparameters for {', '.join(sorted(missing))}")
  return table


def entry(agent: str, robot: str, path: pathlib.Path | None = None) -> dict:
  """``{"params": ..., "study": ...}`` of ``agent`` on ``robot`` (or on the default robot)."""
  search_space(agent)
  table = load(path)
  entries = table["agents"][agent]
  return entries.get(robot, entries[table["default_robot"]])


def values(agent: str, robot: str, path: pathlib.Path | None = None) -> dict:
  """The hyperparameters ``agent`` trains with on ``robot`` (module docstring)."""
  return dict(entry(agent, robot, path)["params"])


def training_settings(params: dict) -> dict:
  """The entries of ``params`` that configure the optimiser."""
  return {name: value for name, value in params.items() if name in TRAINING_PARAMETERS}


def model_settings(params: dict) -> dict:
  """The entries of ``params`` that configure the model (keyword arguments of its factory)."""
  return {name: value for name, value in params.items() if name not in TRAINING_PARAMETERS}


def adopt(agent: str, robot: str, params: dict, study: dict,
          path: pathlib.Path | None = None) -> None:
  """Commits ``params`` (chosen by ``study``) as ``agent``'s values on ``robot``, atomically."""
  path = PATH if path is None else path
  table = load(path)
  check_params(agent, params)
  table["agents"][agent][robot] = {"params": dict(params), "study": study}
  storage.write_atomically(path, json.dumps(table, indent=2, allow_nan=False) + "\n")
