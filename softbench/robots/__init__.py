"""The robot registry: ``make('tendon-3')``, ``make('pneumatic-433')``.

``BENCHMARK_ROBOTS`` are the configurations of the paper; any ``tendon-N`` with N from 1 to
``tendon.MAX_MODULES`` builds.
"""

from softbench.robots.base import SoftArm
from softbench.robots.pneumatic import PneumaticArm
from softbench.robots.tendon import MAX_MODULES, TendonArm

BENCHMARK_ROBOTS = ("tendon-1", "tendon-2", "tendon-3", "tendon-4", "tendon-5", "pneumatic-433")


def make(name: str, **overrides) -> SoftArm:
  """The robot called ``name``, with spec fields replaced by ``overrides``.

  Raises:
    ValueError: unknown or malformed name, or an invalid field value (one line).
  """
  if not isinstance(name, str):
    raise ValueError(f"robot name must be a string, got {name!r}")
  if name.startswith("tendon-"):
    return TendonArm.from_name(name, **_checked(TendonArm, overrides))
  if name == "pneumatic-433":
    return PneumaticArm(**_checked(PneumaticArm, overrides))
  raise ValueError(f"unknown robot {name!r}; choose tendon-N (N = 1 to {MAX_MODULES}) or "
                   f"pneumatic-433")


def _checked(family: type, overrides: dict) -> dict:
  fields = set(family.__dataclass_fields__)
  unknown = sorted(set(overrides) - fields)
  if unknown:
    raise ValueError(f"{family.__name__} has no field {unknown[0]!r}")
  return overrides


__all__ = ["BENCHMARK_ROBOTS", "MAX_MODULES", "PneumaticArm", "SoftArm", "TendonArm", "make"]
