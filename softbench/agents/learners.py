"""How an agent trained on babbling learns: its inverse model and what tuning may change in it.

A ``Learner`` is data, so the agent registry (``softbench.agents``) holds one per learned agent
without importing torch: one progressive column per module (``per_module``, SMPL), or one
centralised model of the whole arm built by ``model`` (``"module:Class"``, imported when the
agent is first built), and the ``search_space`` of its tuned hyperparameters (``softbench tune``
searches it with Optuna; the values in use are in ``hyperparameters.json``).
"""

from collections.abc import Callable
from collections.abc import Mapping
import dataclasses
import importlib
import numbers
from typing import TYPE_CHECKING

from softbench import data

if TYPE_CHECKING:
  from softbench.robots.base import SoftArm


@dataclasses.dataclass(frozen=True)
class LogUniform:
  """A float drawn log-uniformly from [low, high]."""

  low: float
  high: float

  def suggest(self, trial, name: str) -> float:
    return trial.suggest_float(name, self.low, self.high, log=True)

  def contains(self, value) -> bool:
    return (
      isinstance(value, numbers.Real)
      and not isinstance(value, bool)
      and self.low <= value <= self.high
    )

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
    return (
      not isinstance(value, bool)
      and isinstance(value, numbers.Real)
      and any(
        value == option and (isinstance(value, int) or not isinstance(option, int))
        for option in self.values
      )
    )

  def describe(self) -> str:
    return "one of " + ", ".join(f"{value:g}" for value in self.values)


OPTIMISATION = {
  "learning_rate": LogUniform(1e-4, 1e-2),
  "batch_size": Choice((32, 64, 128)),  # 16 left out: it doubles a trial's time (docs/tuning.md).
  "weight_decay": Choice((0.0, 1e-6, 1e-5, 1e-4)),
}
"""The optimiser's tuned settings, shared by every learner (``smpl.training``)."""
RECURRENT = {"hidden_size": Choice((16, 32, 64, 128)), "num_layers": Choice((1, 2, 3))}
"""Width and depth of a recurrent centralised model."""


def views(robot: "SoftArm", per_module: bool) -> list:
  """What the controllers read: module k's inputs for column k (``per_module``), else the whole
  arm's (``softbench.data.View``)."""
  return (
    [data.View.module(robot, k) for k in range(1, robot.num_modules + 1)]
    if per_module
    else [data.View.whole_arm(robot)]
  )


@dataclasses.dataclass(frozen=True)
class Learner:
  """How a learned agent's inverse model is made (module docstring)."""

  per_module: bool
  model: str | None = None
  search_space: Mapping[str, LogUniform | Choice] = dataclasses.field(default_factory=dict)

  def __post_init__(self):
    if self.per_module == (self.model is not None):
      raise ValueError("a learner has either one column per module or a centralised model")

  @property
  def make_model(self) -> Callable | None:
    """The centralised model's factory, ``(input_size, action_size, **settings) -> model``."""
    if self.model is None:
      return None
    module, _, name = self.model.partition(":")
    return getattr(importlib.import_module(module), name)

  def views(self, robot: "SoftArm") -> list:
    return views(robot, self.per_module)
