"""Streams: sequences of robot configurations that a continual learner meets one stage at a time.

A stream fixes, for a tendon family (``tendon`` or ``tendon-local``):

- its configurations, in order: one per stage;
- the data of each stage: that configuration's babbling dataset (data seed
  ``learning.inverse.DATA_SEED``, the profile's sample count), cut into the end effector's view;
- what is scored after each stage: every configuration seen so far, closed loop in physics, on
  the stream's ``task``.

Registered streams:

- ``grow``: 1 to 5 modules (``FAMILY-1`` .. ``FAMILY-5``): the paper's Exp1S;
- ``shrink``: 5 to 1 modules, a module detached at every stage;
- ``degrade``: ``FAMILY-3`` whose distal module's four cables lose gain stage by stage
  (``--fault``'s mechanism, ``softbench.robots.faults``): 100, 75, 50, 25 %;
- ``payload``: ``FAMILY-3`` carrying a rising mass at its tip (``softbench.robots.payload``):
  0, 5, 10, 20 g (the rod weighs 13 g; 20 g lowers the highest tip of random actuation from
  63 mm above the base to 29 mm below it).

``register`` adds a stream from outside the package; tests cover every entry with no new test
code.
"""

from collections.abc import Callable
import dataclasses

from softbench import registries
from softbench import robots
from softbench import suite
from softbench.records.exp1s import DEFAULT_FAMILY
from softbench.records.exp1s import FORGETTING_TASK
from softbench.robots import faults as fault_model

GRAMS_PER_KG = 1000.0
DEGRADED_MODULE = 3  # The distal module of FAMILY-3, whose cables lose gain in ``degrade``.
DEGRADE_GAINS = (1.0, 0.75, 0.5, 0.25)  # Fraction of every cable's healthy gain, per stage.
PAYLOADS_G = (0.0, 5.0, 10.0, 20.0)  # (g) Mass at the tip, per stage.
CABLES_PER_MODULE = 4  # xpos, ypos, xneg, yneg (softbench.robots.faults).


@dataclasses.dataclass(frozen=True)
class Configuration:
  """One stage's robot, and how tables name it (``tendon-2``, ``cables 75 %``, ``10 g``)."""

  label: str
  robot: "robots.SoftArm"

  def describe(self) -> dict:
    """The configuration as a record holds it: label, robot name, faults and payload."""
    return {
      "label": self.label,
      "robot": self.robot.name,
      "faults": [str(fault) for fault in self.robot.faults],
      "payload_kg": self.robot.payload,
    }


@dataclasses.dataclass(frozen=True)
class Stream:
  """A registered stream (module docstring): ``build(family)`` gives its configurations."""

  name: str
  description: str
  build: Callable[[str], tuple[Configuration, ...]]
  task: str = FORGETTING_TASK

  def configurations(self, family: str = DEFAULT_FAMILY) -> tuple[Configuration, ...]:
    """The stream's configurations on tendon family ``family``, one per stage.

    Raises:
      ValueError: an unknown family (one line).
    """
    check_family(family)
    return self.build(family)


def check_family(family: str) -> None:
  if family not in robots.TENDON_FAMILY_NAMES:
    raise ValueError(
      f"unknown tendon family {family!r}; choose one of {', '.join(robots.TENDON_FAMILY_NAMES)}"
    )


def _arms(family: str, module_counts) -> tuple[Configuration, ...]:
  return tuple(
    Configuration(f"{family}-{count}", robots.make(f"{family}-{count}")) for count in module_counts
  )


def _degraded(family: str) -> tuple[Configuration, ...]:
  arm = robots.make(f"{family}-3")
  return tuple(
    Configuration(
      f"cables {gain:.0%}",
      arm.with_faults(
        fault_model.Fault(DEGRADED_MODULE, cable, gain) for cable in range(CABLES_PER_MODULE)
      )
      if gain < 1.0
      else arm,
    )
    for gain in DEGRADE_GAINS
  )


def _loaded(family: str) -> tuple[Configuration, ...]:
  return tuple(
    Configuration(f"{grams:g} g", robots.make(f"{family}-3", payload=grams / GRAMS_PER_KG))
    for grams in PAYLOADS_G
  )


_STREAMS = {
  "grow": Stream(
    "grow",
    "1 to 5 modules, one added per stage (the paper's Exp1S)",
    lambda family: _arms(family, range(1, 6)),
  ),
  "shrink": Stream(
    "shrink",
    "5 to 1 modules, the distal one detached per stage",
    lambda family: _arms(family, range(5, 0, -1)),
  ),
  "degrade": Stream(
    "degrade",
    "3 modules; the distal module's cables keep 100, 75, 50, 25 % of their gain",
    _degraded,
  ),
  "payload": Stream("payload", "3 modules carrying 0, 5, 10, 20 g at the tip", _loaded),
}
STREAMS = tuple(_STREAMS)


def register(stream: Stream) -> None:
  """Adds ``stream`` to the registry (``STREAMS`` is rebound to include it).

  Raises:
    ValueError: the name is taken or malformed, or its task is unknown (one line).
  """
  global STREAMS
  name = stream.name
  registries.check_new_name("stream", name, _STREAMS)
  suite.describe(stream.task)
  _STREAMS[name] = stream
  STREAMS = tuple(_STREAMS)


def get(name: str) -> Stream:
  """The stream called ``name``; raises a one-line ValueError for an unknown one."""
  if name not in _STREAMS:
    raise ValueError(f"unknown stream {name!r}; choose one of {', '.join(STREAMS)}")
  return _STREAMS[name]
