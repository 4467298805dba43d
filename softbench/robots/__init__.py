"""The robot registry: ``make('tendon-3')``, ``make('tendon-local-3')``, ``make('pneumatic-433')``.

``REGISTERED_ROBOTS`` are the configurations of the paper, on both tendon plants; any
``tendon-N`` or ``tendon-local-N`` with N from 1 to ``tendon.MAX_MODULES`` builds.
"""

import dataclasses
import re

from softbench.robots.base import SoftArm
from softbench.robots.pneumatic import PneumaticArm
from softbench.robots.tendon import MAX_MODULES
from softbench.robots.tendon import CableDrivenArm
from softbench.robots.tendon import TendonArm
from softbench.robots.tendon_local import LocalTendonArm

TENDON_FAMILIES = {family.FAMILY: family for family in (TendonArm, LocalTendonArm)}
"""Tendon arm families by name: ``tendon`` routes distal cables through the proximal modules,
``tendon-local`` keeps every cable within its module (the paper's simulator)."""


@dataclasses.dataclass(frozen=True)
class Family:
  """Robots that share a builder: ``name-N`` for N modules (``numbered``), or ``name`` alone.

  Attributes:
    name: The family's name, and the prefix of its robots' names.
    arm: The arm class; numbered families build through ``arm.from_name(name)``.
    numbered: Whether names carry a number of modules.
    benchmark: The family's robots that the benchmark (``softbench robots``) lists.
  """

  name: str
  arm: type[SoftArm]
  numbered: bool
  benchmark: tuple[str, ...]

  def __post_init__(self):
    if not re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", self.name):
      raise ValueError(f"family names are lowercase words joined by hyphens, got {self.name!r}")

  @property
  def usage(self) -> str:
    return f"{self.name}-N" if self.numbered else self.name

  @property
  def pattern(self) -> str:
    """A regular expression of the names the family answers (as records hold them)."""
    return f"{self.name}-[1-9][0-9]*" if self.numbered else self.name

  @property
  def example(self) -> str:
    """A small robot that shows the family's layout: its second registered robot (two modules on a
    numbered family, so that observations hold more than one module), or its only one."""
    return self.benchmark[min(1, len(self.benchmark) - 1)]

  def answers(self, name: str) -> bool:
    return name.startswith(f"{self.name}-") if self.numbered else name == self.name

  def build(self, name: str, overrides: dict) -> SoftArm:
    if self.numbered:
      return self.arm.from_name(name, **_checked(self.arm, overrides))
    return self.arm(**_checked(self.arm, overrides))


BENCHMARK_MODULES = range(1, 6)  # N of the benchmark tendon arms, tendon-1 .. tendon-5.
FAMILIES = (
  *(
    Family(name, arm, True, tuple(f"{name}-{n}" for n in BENCHMARK_MODULES))
    for name, arm in TENDON_FAMILIES.items()
  ),
  Family("pneumatic-433", PneumaticArm, False, ("pneumatic-433",)),
)
"""Every robot family; a new one is an arm class and one entry here. A name belongs to the
longest family name it starts with (``tendon-local-x`` is a malformed ``tendon-local`` name)."""
REGISTERED_ROBOTS = tuple(robot for family in FAMILIES for robot in family.benchmark)
LEADERBOARD_ROBOTS = ("tendon-3", "tendon-local-3", "pneumatic-433")
"""The registered robots the leaderboard ranks agents on: the paper's (Exp2S tracking on
tendon-3, reaching on pneumatic-433) and tendon-3's module-local plant, the paper simulator's
arm."""
NAME_PATTERN = f"^({'|'.join(family.pattern for family in FAMILIES)})$"
"""Every robot name any family answers, as a regular expression (for the records' schema)."""


def family_of(name: str) -> Family | None:
  """The family that answers ``name`` (its longest name first), or None."""
  for family in sorted(FAMILIES, key=lambda family: len(family.name), reverse=True):
    if family.answers(name):
      return family
  return None


def tendon_family(name: str) -> type[CableDrivenArm] | None:
  """The tendon arm class whose names ``name`` has the form of, or None."""
  family = family_of(name)
  return family.arm if family is not None and family.name in TENDON_FAMILIES else None


def make(name: str, **overrides) -> SoftArm:
  """The robot called ``name``, with spec fields replaced by ``overrides``.

  Raises:
    ValueError: unknown or malformed name, or an invalid field value (one line).
  """
  if not isinstance(name, str):
    raise ValueError(f"robot name must be a string, got {name!r}")
  if family := family_of(name):
    return family.build(name, overrides)
  raise ValueError(
    f"unknown robot {name!r}; choose "
    f"{' or '.join(family.usage for family in FAMILIES)} (N = 1 to "
    f"{MAX_MODULES})"
  )


def _checked(family: type, overrides: dict) -> dict:
  fields = {field.name for field in dataclasses.fields(family)}
  unknown = sorted(set(overrides) - fields)
  if unknown:
    raise ValueError(f"{family.__name__} has no field {unknown[0]!r}")
  return overrides


__all__ = [
  "REGISTERED_ROBOTS",
  "FAMILIES",
  "MAX_MODULES",
  "NAME_PATTERN",
  "TENDON_FAMILIES",
  "CableDrivenArm",
  "Family",
  "LocalTendonArm",
  "PneumaticArm",
  "SoftArm",
  "TendonArm",
  "family_of",
  "make",
  "tendon_family",
]
