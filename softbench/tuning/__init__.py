"""Hyperparameter tuning with Optuna (``softbench tune``): the same study for every learned agent.

``settings(...)`` checks a study's settings, ``run(settings)`` adds trials until the budget is
spent and returns the study's summary, ``confirm`` trains its previous and best values at the
profile's full epoch budget, ``write_summary`` saves it and ``adopt`` commits the best values as
the agent's hyperparameters (``softbench.agents.hyperparameters``); ``tune`` does all of it as
``softbench tune`` asks and prints the report (``softbench.tuning.report``). See
``softbench.tuning.study`` for the objective, sampler and pruner.
"""

from softbench.tuning.definition import DEFAULT_TRIALS
from softbench.tuning.definition import MAX_TRIALS
from softbench.tuning.definition import TuneSettings
from softbench.tuning.definition import default_storage
from softbench.tuning.definition import settings
from softbench.tuning.study import confirm
from softbench.tuning.study import run
from softbench.tuning.study import tune
from softbench.tuning.summary_files import adopt
from softbench.tuning.summary_files import summary_path
from softbench.tuning.summary_files import write_summary

__all__ = [
  "DEFAULT_TRIALS",
  "MAX_TRIALS",
  "TuneSettings",
  "adopt",
  "confirm",
  "default_storage",
  "run",
  "settings",
  "summary_path",
  "tune",
  "write_summary",
]
