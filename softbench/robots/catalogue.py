"""What the registry knows of every robot without building it, and without MuJoCo: the families,
their names, each robot's module count and nominal length.

The records and the leaderboard read robots through this module only (``tests/test_layers.py``),
so that reading results never loads a simulator; ``softbench.robots.make`` builds the arm itself,
whose class a family names by its import path (Gymnasium's ``entry_point`` convention) and loads
on first use.
"""

import dataclasses
import importlib
import re
from typing import Any

MAX_MODULES = 10  # Largest N of a tendon-N arm that builds; N = 1 .. 5 are the benchmark ones.
TENDON_MODULE_LENGTH = 0.05  # (m) Paper: "Each module has a length of 50 mm".
PNEUMATIC_MODULE_LENGTH = 0.08  # (m) Paper: "Each actuator is 80mm long".
PNEUMATIC_BELLOWS = (4, 3, 3)  # Paper: 4 at 90 degrees at the base, then 3 at 120 degrees.
BENCHMARK_MODULES = range(1, 6)  # N of the benchmark tendon arms, tendon-1 .. tendon-5.


@dataclasses.dataclass(frozen=True)
class Family:
  """Robots that share a builder: ``name-N`` for N modules (``numbered``), or ``name`` alone.

  Attributes:
    name: The family's name, and the prefix of its robots' names.
    arm_class: The arm class's import path, ``module:Class``; numbered families build through
      ``Class.from_name(name)``.
    numbered: Whether names carry a number of modules.
    benchmark: The family's robots that the benchmark (``softbench robots``) lists.
    module_length: Each module's nominal rest length (m), the arm class's default.
    modules: The module count of an unnumbered family's robot (None for a numbered family).
  """

  name: str
  arm_class: str
  numbered: bool
  benchmark: tuple[str, ...]
  module_length: float
  modules: int | None = None

  def __post_init__(self):
    if not re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", self.name):
      raise ValueError(f"family names are lowercase words joined by hyphens, got {self.name!r}")
    if self.numbered != (self.modules is None):
      raise ValueError(f"family {self.name!r}: modules is given for unnumbered families only")

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

  @property
  def arm(self) -> Any:
    """The arm class (imported on first use: it loads MuJoCo)."""
    module, _, name = self.arm_class.partition(":")
    return getattr(importlib.import_module(module), name)

  def answers(self, name: str) -> bool:
    return name.startswith(f"{self.name}-") if self.numbered else name == self.name

  def num_modules(self, name: str) -> int:
    """The module count of robot ``name`` of this family.

    Raises:
      ValueError: a malformed name or a count out of range (one line).
    """
    if not self.numbered:
      return self.modules
    # Canonical names only: ASCII digits, no leading zero, no surrounding space.
    match = re.fullmatch(rf"{re.escape(self.name)}-(0|[1-9][0-9]{{0,3}})", name, re.ASCII)
    if not match:
      raise ValueError(
        f"malformed {self.name} arm name {name[:40]!r}; expected "
        f"{self.name}-N with N from 1 to {MAX_MODULES}"
      )
    count = int(match.group(1))
    if not 1 <= count <= MAX_MODULES:
      raise ValueError(f"{self.name} arms have 1 to {MAX_MODULES} modules, got {count}")
    return count


FAMILIES = (
  *(
    Family(
      name, arm_class, True, tuple(f"{name}-{n}" for n in BENCHMARK_MODULES), TENDON_MODULE_LENGTH
    )
    for name, arm_class in (
      ("tendon", "softbench.robots.tendon:TendonArm"),
      ("tendon-local", "softbench.robots.tendon_local:LocalTendonArm"),
    )
  ),
  Family(
    "pneumatic-433",
    "softbench.robots.pneumatic:PneumaticArm",
    False,
    ("pneumatic-433",),
    PNEUMATIC_MODULE_LENGTH,
    modules=len(PNEUMATIC_BELLOWS),
  ),
)
"""Every robot family; a new one is an arm class and one entry here. A name belongs to the
longest family name it starts with (``tendon-local-x`` is a malformed ``tendon-local`` name)."""
TENDON_FAMILY_NAMES = ("tendon", "tendon-local")
"""The tendon arm families: ``tendon`` routes distal cables through the proximal modules,
``tendon-local`` keeps every cable within its module (the paper's simulator)."""
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


def family_named(family_name: str) -> Family:
  """The family called ``family_name`` (KeyError for none)."""
  return {family.name: family for family in FAMILIES}[family_name]


def known_family(name: object) -> Family:
  """The family that answers robot name ``name``, whose form it does not check yet.

  Raises:
    ValueError: not a string, or no family answers it (one line).
  """
  if not isinstance(name, str):
    raise ValueError(f"robot name must be a string, got {name!r}")
  family = family_of(name)
  if family is None:
    raise ValueError(
      f"unknown robot {name!r}; choose "
      f"{' or '.join(family.usage for family in FAMILIES)} (N = 1 to {MAX_MODULES})"
    )
  return family


def checked_family(name: object) -> Family:
  """The family of robot ``name``, whose name it checks as ``softbench.robots.make`` does.

  Raises:
    ValueError: not a string, an unknown family, or a malformed name (one line).
  """
  family = known_family(name)
  family.num_modules(name)
  return family


def num_modules(name: str) -> int:
  """The module count of robot ``name`` (as ``make(name).num_modules``, without building it).

  Raises:
    ValueError: an unknown or malformed name (one line).
  """
  return known_family(name).num_modules(name)


def length(name: str) -> float:
  """The nominal rest length of robot ``name`` (m; as ``make(name).length``).

  Raises:
    ValueError: an unknown or malformed name (one line).
  """
  family = known_family(name)
  return float(sum((family.module_length,) * family.num_modules(name)))  # As SoftArm.length sums.


def is_tendon(name: str) -> bool:
  """Whether ``name`` has the form of a tendon arm's name (of a tendon family)."""
  family = family_of(name) if isinstance(name, str) else None
  return family is not None and family.name in TENDON_FAMILY_NAMES
