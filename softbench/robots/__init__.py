"""The robot registry: ``make('tendon-3')``, ``make('tendon-local-3')``, ``make('pneumatic-433')``.

``BENCHMARK_ROBOTS`` are the configurations of the paper, on both tendon plants; any
``tendon-N`` or ``tendon-local-N`` with N from 1 to ``tendon.MAX_MODULES`` builds.
"""

import dataclasses

from softbench.robots.base import SoftArm
from softbench.robots.pneumatic import PneumaticArm
from softbench.robots.tendon import MAX_MODULES, CableDrivenArm, TendonArm
from softbench.robots.tendon_local import LocalTendonArm

TENDON_FAMILIES = {family.FAMILY: family for family in (TendonArm, LocalTendonArm)}
"""Tendon arm families by name: ``tendon`` routes distal cables through the proximal modules,
``tendon-local`` keeps every cable within its module (the paper's simulator)."""
BENCHMARK_MODULES = range(1, 6)  # N of the benchmark tendon arms, tendon-1 .. tendon-5.
BENCHMARK_ROBOTS = (*(f"{family}-{n}" for family in TENDON_FAMILIES for n in BENCHMARK_MODULES),
                    "pneumatic-433")


def tendon_family(name: str) -> type[CableDrivenArm] | None:
  """The tendon family whose names ``name`` has the form of (``tendon-local-x`` is a malformed
  ``tendon-local`` name, not a ``tendon`` one), or None."""
  for family in sorted(TENDON_FAMILIES, key=len, reverse=True):
    if name.startswith(f"{family}-"):
      return TENDON_FAMILIES[family]
  return None


def make(name: str, **overrides) -> SoftArm:
  """The robot called ``name``, with spec fields replaced by ``overrides``.

  Raises:
    ValueError: unknown or malformed name, or an invalid field value (one line).
  """
  if not isinstance(name, str):
    raise ValueError(f"robot name must be a string, got {name!r}")
  if family := tendon_family(name):
    return family.from_name(name, **_checked(family, overrides))
  if name == "pneumatic-433":
    return PneumaticArm(**_checked(PneumaticArm, overrides))
  raise ValueError(f"unknown robot {name!r}; choose tendon-N or tendon-local-N (N = 1 to "
                   f"{MAX_MODULES}) or pneumatic-433")


def _checked(family: type, overrides: dict) -> dict:
  fields = {field.name for field in dataclasses.fields(family)}
  unknown = sorted(set(overrides) - fields)
  if unknown:
    raise ValueError(f"{family.__name__} has no field {unknown[0]!r}")
  return overrides


__all__ = ["BENCHMARK_ROBOTS", "MAX_MODULES", "TENDON_FAMILIES", "CableDrivenArm",
           "LocalTendonArm", "PneumaticArm", "SoftArm", "TendonArm", "make", "tendon_family"]
