"""The continual strategy registry: ``make(name, setting)`` and ``STRATEGIES``.

A strategy is one file with a ``STRATEGY`` class (``base.Strategy``) and one line here:

- ``smpl``: the progressive network, a column per configuration (``strategies.smpl``);
- ``finetune``: one shared network trained stage after stage (``strategies.finetune``);
- ``ewc``: the same with elastic weight consolidation (``strategies.ewc``);
- ``replay``: the same with a buffer of earlier stages' windows (``strategies.replay``);
- ``independent``: a fresh network per configuration (``strategies.independent``);
- ``joint``: one network trained on every configuration at once, not continual: the upper bound
  (``strategies.joint``).

``register`` adds a strategy from outside the package; tests cover every entry with no new test
code. The registry imports no torch (the command line's help lists it); ``strategies.base`` holds
what a strategy is.
"""

import collections
import importlib

from softbench import registries

StrategyEntry = collections.namedtuple("StrategyEntry", ["module", "description"])
"""A strategy: the module whose ``STRATEGY`` class it is, and a one-line description."""

_STRATEGIES = {
  "smpl": StrategyEntry(
    "softbench.continual.strategies.smpl", "SMPL: a progressive LSTM column per configuration"
  ),
  "finetune": StrategyEntry(
    "softbench.continual.strategies.finetune", "one shared LSTM trained stage after stage"
  ),
  "ewc": StrategyEntry(
    "softbench.continual.strategies.ewc", "the shared LSTM with elastic weight consolidation"
  ),
  "replay": StrategyEntry(
    "softbench.continual.strategies.replay", "the shared LSTM replaying earlier stages' windows"
  ),
  "independent": StrategyEntry(
    "softbench.continual.strategies.independent", "a fresh LSTM per configuration (no transfer)"
  ),
  "joint": StrategyEntry(
    "softbench.continual.strategies.joint",
    "one LSTM trained on every configuration at once (not continual: the upper bound)",
  ),
}
STRATEGIES = tuple(_STRATEGIES)
REFERENCE = "independent"  # Forward transfer is measured against it.


def register(name: str, entry: StrategyEntry) -> None:
  """Adds strategy ``name`` (``STRATEGIES`` is rebound to include it).

  Raises:
    ValueError: the name is taken or malformed (one line).
  """
  global STRATEGIES
  registries.check_new_name("strategy", name, _STRATEGIES)
  _STRATEGIES[name] = entry
  STRATEGIES = tuple(_STRATEGIES)


def describe(name: str) -> StrategyEntry:
  if name not in _STRATEGIES:
    raise ValueError(f"unknown continual strategy {name!r}; choose one of {', '.join(STRATEGIES)}")
  return _STRATEGIES[name]


def strategy_class(name: str) -> type:
  """The ``base.Strategy`` class of strategy ``name``; raises a one-line ValueError for an unknown
  one."""
  return importlib.import_module(describe(name).module).STRATEGY


def make(name: str, setting):
  """A fresh strategy ``name`` (a ``base.Strategy``) for a run of ``setting`` (a
  ``base.Setting``)."""
  return strategy_class(name)(setting)


__all__ = [
  "REFERENCE",
  "STRATEGIES",
  "StrategyEntry",
  "describe",
  "make",
  "register",
  "strategy_class",
]
