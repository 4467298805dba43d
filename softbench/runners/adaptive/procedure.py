"""The staged module activation of the paper's adaptive reaching experiment, as a state machine.

Nothing here knows about physics: a driver asks for the next stage, runs the arm with that
stage's active modules, and reports the settled position error; the procedure decides what comes
next (paper, section "Adaptive Module Activation Experiment"; SPEC 7):

1. ``target``: the target module acts alone; the others get zero actuation.
2. While the error is above ``threshold``, the neighbouring modules are tried one at a time,
   outwards from the target module, the preceding one first (on a 3-module arm with target
   module 2: module 1, then module 3). A tried module is kept on only if its stage lowers the
   error below that of the modules kept so far (SPEC 7: "switching on neighbouring modules only
   while they reduce the error"; the paper states the rule for the following module, and it
   applies here to the preceding one as well).
3. ``revert``: if the last module tried was not kept, the arm runs once more with the kept
   modules, so that it ends in the configuration the procedure chose; the error of that stage is
   the final error. Otherwise the last stage's error is the final error.
"""

import dataclasses
import math
import numbers

TARGET = "target"  # The target module alone.
PRECEDING = "preceding"  # A module nearer the base than the target module is tried.
FOLLOWING = "following"  # A module nearer the tip than the target module is tried.
REVERT = "revert"  # Back to the kept modules after the last tried module was not kept.


@dataclasses.dataclass(frozen=True)
class Stage:
  """One stage: the modules that act (1-based, ascending) and the module it tries, if any."""

  kind: str
  active: tuple[int, ...]
  candidate: int | None = None

  @property
  def label(self) -> str:
    """The same for every target, so that stages can be compared across targets."""
    if self.kind == TARGET:
      return f"module {self.active[0]} alone"
    if self.kind == REVERT:
      return "back to the kept modules"
    return f"+ module {self.candidate}"


@dataclasses.dataclass(frozen=True)
class StageResult:
  """A stage, its settled error, and whether the module it tried was kept (None: tried none)."""

  stage: Stage
  error: float
  kept: bool | None


def candidates(num_modules: int, target_module: int) -> tuple[int, ...]:
  """The modules to try after the target module: outwards from it, the preceding one first."""
  order = []
  for distance in range(1, num_modules):
    order += [
      module
      for module in (target_module - distance, target_module + distance)
      if 1 <= module <= num_modules
    ]
  return tuple(order)


class ActivationProcedure:
  """Decides which modules act in each stage (module docstring).

  Use: ``while (stage := procedure.next_stage()) is not None: procedure.report(error)``, where
  ``error`` is the settled position error of a stage run with ``stage.active``; ``threshold``
  is in the same unit.
  """

  def __init__(self, num_modules: int, target_module: int, threshold: float):
    if isinstance(num_modules, bool) or not isinstance(num_modules, int) or num_modules < 1:
      raise ValueError(f"num_modules must be a positive integer, got {num_modules!r}")
    if (
      isinstance(target_module, bool)
      or not isinstance(target_module, int)
      or not 1 <= target_module <= num_modules
    ):
      raise ValueError(f"target module must be 1 to {num_modules}, got {target_module!r}")
    if not _non_negative(threshold):
      raise ValueError(f"threshold must be a non-negative number, got {threshold!r}")
    self.num_modules = num_modules
    self.target_module = target_module
    self.threshold = float(threshold)
    self._untried = list(candidates(num_modules, target_module))
    self._kept = (target_module,)
    self._kept_error = math.inf  # The error of the stage that established the kept modules.
    self._results: list[StageResult] = []
    self._pending: Stage | None = Stage(TARGET, self._kept)

  @property
  def max_stages(self) -> int:
    """The most stages any run can take: the target alone, each candidate, one revert."""
    return 2 + len(candidates(self.num_modules, self.target_module))

  @property
  def labels(self) -> tuple[str, ...]:
    """Every stage label this procedure can produce, in the order stages happen."""
    tried = [self._trial(module) for module in candidates(self.num_modules, self.target_module)]
    return tuple(
      stage.label
      for stage in [Stage(TARGET, (self.target_module,)), *tried, Stage(REVERT, self._kept)]
    )

  @property
  def active(self) -> tuple[int, ...]:
    """The modules kept on so far (at the end: the modules the procedure chose)."""
    return self._kept

  @property
  def results(self) -> tuple[StageResult, ...]:
    return tuple(self._results)

  @property
  def done(self) -> bool:
    return self._pending is None

  @property
  def final_error(self) -> float:
    """The error of the last stage, which ran with the chosen modules."""
    if not self.done:
      raise ValueError("the procedure has not finished; report every stage first")
    return self._results[-1].error

  def next_stage(self) -> Stage | None:
    """The stage to run now, or None when the procedure has finished."""
    return self._pending

  def report(self, error: float) -> None:
    """The settled error of the stage ``next_stage`` gave.

    Raises:
      ValueError: no stage is running, or the error is negative or not finite.
    """
    if self._pending is None:
      raise ValueError("no stage is running; call next_stage first")
    if not _non_negative(error):
      raise ValueError(f"error must be a non-negative finite number, got {error!r}")
    stage, self._pending = self._pending, None
    kept = None
    if stage.kind in (PRECEDING, FOLLOWING):
      kept = error < self._kept_error
      if kept:
        self._kept, self._kept_error = stage.active, float(error)
    elif stage.kind == TARGET:
      self._kept_error = float(error)
    self._results.append(StageResult(stage, float(error), kept))
    self._pending = self._following_stage(stage)

  def _following_stage(self, last: Stage) -> Stage | None:
    """The stage after ``last`` has been reported, or None if the procedure is over."""
    if last.kind == REVERT:
      return None
    if self._kept_error > self.threshold and self._untried:
      return self._trial(self._untried.pop(0))
    return Stage(REVERT, self._kept) if last.active != self._kept else None

  def _trial(self, module: int) -> Stage:
    """The stage that tries ``module`` beside the kept modules."""
    kind = PRECEDING if module < self.target_module else FOLLOWING
    return Stage(kind, tuple(sorted(self._kept + (module,))), module)


def _non_negative(value) -> bool:
  return (
    isinstance(value, numbers.Real)
    and not isinstance(value, bool)
    and math.isfinite(value)
    and value >= 0
  )
