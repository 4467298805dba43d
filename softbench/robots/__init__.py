"""The robot registry: ``make('tendon-3')``, ``make('tendon-local-3')``, ``make('pneumatic-433')``.

``REGISTERED_ROBOTS`` are the configurations of the paper, on both tendon plants; any
``tendon-N`` or ``tendon-local-N`` with N from 1 to ``MAX_MODULES`` builds. What is known of a
robot without building it (families, names, module counts, lengths) is in ``catalogue`` and
imports no MuJoCo; the arm classes (``TendonArm``, ``PneumaticArm``, ...) and ``make`` load it on
first use.
"""

import dataclasses

import lazy_loader

from softbench.robots.catalogue import BENCHMARK_MODULES
from softbench.robots.catalogue import FAMILIES
from softbench.robots.catalogue import LEADERBOARD_ROBOTS
from softbench.robots.catalogue import MAX_MODULES
from softbench.robots.catalogue import NAME_PATTERN
from softbench.robots.catalogue import REGISTERED_ROBOTS
from softbench.robots.catalogue import TENDON_FAMILY_NAMES
from softbench.robots.catalogue import Family
from softbench.robots.catalogue import checked_family
from softbench.robots.catalogue import family_named
from softbench.robots.catalogue import family_of
from softbench.robots.catalogue import is_tendon
from softbench.robots.catalogue import known_family
from softbench.robots.catalogue import length
from softbench.robots.catalogue import num_modules

# The arm classes and the modules that build arms load MuJoCo: each is imported on first use
# (``lazy_loader``), ``robots.tendon`` as ``robots.TendonArm``.
__getattr__, __dir__, _LOADED_ON_USE = lazy_loader.attach(
  __name__,
  submodules=["base", "chain", "faults", "payload", "pneumatic", "tendon", "tendon_local"],
  submod_attrs={
    "base": ["SoftArm"],
    "tendon": ["CableDrivenArm", "TendonArm"],
    "tendon_local": ["LocalTendonArm"],
    "pneumatic": ["PneumaticArm"],
  },
)


def make(name: str, **overrides):
  """The robot called ``name`` (a ``SoftArm``), with spec fields replaced by ``overrides``.

  Raises:
    ValueError: unknown or malformed name, or an invalid field value (one line).
  """
  family = known_family(name)  # The arm class parses the name (from_name) after the overrides.
  arm = family.arm
  fields = {field.name for field in dataclasses.fields(arm)}
  unknown = sorted(set(overrides) - fields)
  if unknown:
    raise ValueError(f"{arm.__name__} has no field {unknown[0]!r}")
  if family.numbered:
    return arm.from_name(name, **overrides)
  return arm(**overrides)


__all__ = _LOADED_ON_USE + [
  "BENCHMARK_MODULES",
  "FAMILIES",
  "LEADERBOARD_ROBOTS",
  "MAX_MODULES",
  "NAME_PATTERN",
  "REGISTERED_ROBOTS",
  "TENDON_FAMILY_NAMES",
  "CableDrivenArm",
  "Family",
  "LocalTendonArm",
  "PneumaticArm",
  "SoftArm",
  "TendonArm",
  "checked_family",
  "family_named",
  "family_of",
  "is_tendon",
  "known_family",
  "length",
  "make",
  "num_modules",
]
