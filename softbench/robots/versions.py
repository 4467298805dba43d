"""Physics versions: which simulator and which backbone made a record, a dataset or a checkpoint.

A physics version names the MuJoCo engine and the tendon arms' backbone that every result of that
version was simulated with. Results of different versions are never mixed: records carry their
version, caches and the zoo key by it, and Gymnasium ids end in it
(``softbench/tendon-3-spiral-v1``).

- ``v0``: MuJoCo 3.17 with the ``mujoco.elasticity.cable`` plugin (records up to 2026-12-06).
  MuJoCo 4 removed the plugin, so v0 runs only where the old stack is installed
  (``make install-v0``, docs/physics-versions.md).
- ``v1``: MuJoCo 4 with the plugin-free rod (``softbench.robots.chain``), equal to the cable plugin
  in force to rounding; it also runs on batched and GPU simulators, which take no plugins.

The installed MuJoCo decides the current version; one process runs one version.
"""

import dataclasses
import functools
from importlib import metadata


@dataclasses.dataclass(frozen=True)
class PhysicsVersion:
  """One physics version.

  Attributes:
    name: ``v0``, ``v1``, ...; also the suffix of the Gymnasium ids.
    engine: The MuJoCo releases it runs on, as a pip requirement.
    engine_major: MuJoCo's major version, which tells the installed version apart.
    backbone: The tendon arms' backbone (``softbench.robots.tendon.BACKBONES``).
    description: One line for listings and the leaderboard.
    install: How to get the stack it runs on.
    legacy_step: Whether an environment's control step runs dm_control's legacy stepping
      (``mj_step2``, ``mj_step`` for the rest, ``mj_step1``; after a reset it continues from
      dm_control's forward pass with actuation disabled) instead of ``mj_step``. The two agree
      bit for bit on the tendon arms (Euler) and differ by up to 2e-5 m on the pneumatic arm
      (implicitfast) after a control period. v0's records were made with it; from v1 every
      stepping path (environments, babbling, references, ``ArmBatch``) runs ``mj_step``.
  """

  name: str
  engine: str
  engine_major: int
  backbone: str
  description: str
  install: str
  legacy_step: bool


VERSIONS = {
  version.name: version
  for version in (
    PhysicsVersion(
      "v0",
      "mujoco>=3.17,<4",
      3,
      "cable",
      "MuJoCo 3.17 + cable plugin",
      "make install-v0 (the old stack in .venv-v0: constraints-v0.txt)",
      legacy_step=True,
    ),
    PhysicsVersion(
      "v1",
      "mujoco>=4.0.1,<5",
      4,
      "rod",
      "MuJoCo 4 + plugin-free rod",
      "make install (the current stack in .venv: constraints.txt)",
      legacy_step=False,
    ),
  )
}
"""Every physics version, oldest first."""
FIRST = "v0"
LATEST = "v1"


@functools.cache
def engine_version() -> str:
  """The installed MuJoCo's version, e.g. ``4.0.1`` (from its package's metadata: reading it
  loads no simulator, so the records and the leaderboard know the version without MuJoCo)."""
  return metadata.version("mujoco")


def cable_plugin_missing() -> str:
  """Why a cable backbone does not build here (one line)."""
  return (
    "the cable backbone needs MuJoCo 3's cable plugin (physics v0), which MuJoCo "
    f"{engine_version()} lacks; use backbone='rod' or install the old stack: "
    + VERSIONS["v0"].install
  )


def engine_major() -> int:
  """The installed MuJoCo's major version."""
  return int(engine_version().split(".")[0])


def current() -> PhysicsVersion:
  """The version the installed MuJoCo runs."""
  major = engine_major()
  for version in VERSIONS.values():
    if version.engine_major == major:
      return version
  return VERSIONS[LATEST] if major > VERSIONS[LATEST].engine_major else VERSIONS[FIRST]


@functools.cache
def cable_plugin_available() -> bool:
  """Whether this MuJoCo has the ``mujoco.elasticity.cable`` plugin (a model that asks for it
  loads)."""
  import mujoco  # The engine itself, only here: the rest of this module reads metadata.

  try:
    mujoco.MjModel.from_xml_string(_CABLE_PROBE)
  except ValueError:
    return False
  return True


_CABLE_PROBE = '<mujoco><extension><plugin plugin="mujoco.elasticity.cable"/></extension></mujoco>'


def named(name: str) -> PhysicsVersion:
  """The version called ``name``, installed or not.

  Raises:
    ValueError: no version has that name (one line).
  """
  if name not in VERSIONS:
    raise ValueError(f"unknown physics version {name!r}; choose from {', '.join(VERSIONS)}")
  return VERSIONS[name]


def check(name: str) -> PhysicsVersion:
  """The version called ``name`` if this installation runs it.

  Raises:
    ValueError: unknown name, or a version whose stack is not installed (one line, saying how to
      install it).
  """
  version = named(name)
  if version != current():
    raise ValueError(
      f"physics {name} ({version.description}) needs {version.engine}, but MuJoCo "
      f"{engine_version()} is installed (physics {current().name}); {version.install}"
    )
  return version
