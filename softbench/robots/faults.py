"""Actuator faults: a degraded actuator (gain reduced to a fraction) or a punctured one (gain 0).

A fault names a module (1 at the base), an actuator within it (0-based) and a gain in [0, 1]; the
text form is ``MODULE:ACTUATOR:GAIN``, e.g. ``2:0:0.3``. An actuator is one MuJoCo actuator, and
actuator i of a module sits at 360·i/n degrees around its axis (n actuators in the module), as the
model names them:

- tendon arms: a cable and its motor, n = 4: 0 ``xpos``, 1 ``ypos``, 2 ``xneg``, 3 ``yneg``. Each
  cable has a motor of its own, so a real fault (a frayed cable, a weak motor) hits one cable, not
  the antagonistic pair that shares an action entry; the arm then still bends fully away from the
  faulty cable but only a fraction towards it. A fault of a whole action channel is two faults
  (``2:0:G`` and ``2:2:G`` for module 2's x axis).
- the pneumatic arm: a bellows, n = 4, 3, 3 (``module{m}_bellows{i+1}``).

The fault multiplies the actuator's gain (``gainprm[0]`` in the MJCF) by the fault's gain, and
nothing else changes in the model:

- a cable's tension is ``gain · max(0, ±a) · Tmax``; gain 0 is a snapped cable (no force);
- a bellows pulls its tendon with ``k (L0 + gain · ΔL(a) - length) - c · velocity``, so its rest
  length changes by ``gain`` times the commanded change, which is the length change of ``gain``
  times the commanded pressure (the pressure-length map is linear on either side of 0 kPa): a
  leak. Gain 0 is a punctured bellows at ambient pressure: no force from pressure, but still the
  passive spring of its silicone body.

The MJCF stores numbers with 6 significant digits, so the faulty gain is exact to that precision.
A gain of 1 leaves the model identical; the dataset, reference and checkpoint caches tell faulty
robots apart through the hash of their MJCF.
"""

import dataclasses
import math
import numbers
import re

import mujoco

_FAULT_PATTERN = re.compile(r"^\s*([^:]+):([^:]+):([^:]+)\s*$")
FAULT_FORMAT = "MODULE:ACTUATOR:GAIN, e.g. 2:0:0.3"


@dataclasses.dataclass(frozen=True)
class Fault:
  """One faulty actuator.

  Attributes:
    module: Module of the actuator, from 1 at the base.
    actuator: Index of the actuator within its module, from 0 (see the module docstring).
    gain: Fraction of the healthy gain left, in [0, 1]; 0 is a punctured actuator.
  """

  module: int
  actuator: int
  gain: float

  def __post_init__(self):
    if (
      isinstance(self.module, bool)
      or not isinstance(self.module, numbers.Integral)
      or self.module < 1
    ):
      raise ValueError(f"fault module must be an integer from 1, got {self.module!r}")
    if (
      isinstance(self.actuator, bool)
      or not isinstance(self.actuator, numbers.Integral)
      or self.actuator < 0
    ):
      raise ValueError(f"fault actuator must be an integer from 0, got {self.actuator!r}")
    if (
      isinstance(self.gain, bool)
      or not isinstance(self.gain, numbers.Real)
      or not math.isfinite(self.gain)
      or not 0.0 <= self.gain <= 1.0
    ):
      raise ValueError(f"fault gain must lie in [0, 1] (0: punctured), got {self.gain!r}")
    object.__setattr__(self, "gain", float(self.gain) + 0.0)  # A float, and -0.0 becomes 0.0.

  @property
  def punctured(self) -> bool:
    return self.gain == 0.0

  def __str__(self) -> str:
    return f"{self.module}:{self.actuator}:{self.gain:g}"


def parse(text: str) -> Fault:
  """The fault of ``MODULE:ACTUATOR:GAIN``; raises a one-line ValueError for bad text."""
  match = _FAULT_PATTERN.match(text) if isinstance(text, str) else None
  if not match:
    raise ValueError(f"malformed fault {text!r}; expected {FAULT_FORMAT}")
  module, actuator, gain = (part.strip() for part in match.groups())
  for name, part in (("module", module), ("actuator", actuator)):
    if not re.fullmatch(r"[+-]?\d+", part):
      raise ValueError(f"fault {text!r}: {name} must be an integer, got {part!r}")
  try:
    value = float(gain)
  except ValueError:
    raise ValueError(f"fault {text!r}: gain must be a number in [0, 1], got {gain!r}") from None
  try:
    return Fault(int(module), int(actuator), value)
  except ValueError as error:
    raise ValueError(f"fault {text!r}: {str(error).removeprefix('fault ')}") from None


def module_actuators(robot) -> list[list[int]]:
  """MuJoCo actuator indices of each module of ``robot`` (a ``SoftArm``), in order; the i-th of a
  module is its actuator i."""
  slices = robot.module_action_slices()
  groups = [[] for _ in slices]
  for index, actuator_map in enumerate(robot.actuator_maps()):
    module = next(
      k for k, part in enumerate(slices) if part.start <= actuator_map.action_index < part.stop
    )
    groups[module].append(index)
  return groups


def check(robot, faults: tuple[Fault, ...]) -> None:
  """Raises a one-line ValueError unless every fault names an actuator of ``robot`` once."""
  if not isinstance(faults, tuple) or not all(isinstance(fault, Fault) for fault in faults):
    raise ValueError(f"faults must be a tuple of Fault, got {faults!r}")
  groups = module_actuators(robot)
  seen = set()
  for fault in faults:
    if fault.module > len(groups):
      raise ValueError(
        f"fault {fault}: {robot.name} has modules 1 to {len(groups)}, not {fault.module}"
      )
    count = len(groups[fault.module - 1])
    if fault.actuator >= count:
      raise ValueError(
        f"fault {fault}: module {fault.module} of {robot.name} has actuators 0 to "
        f"{count - 1}, not {fault.actuator}"
      )
    if (fault.module, fault.actuator) in seen:
      raise ValueError(
        f"fault {fault}: actuator {fault.actuator} of module {fault.module} is "
        f"given more than one fault"
      )
    seen.add((fault.module, fault.actuator))


def actuator_index(robot, fault: Fault) -> int:
  """The MuJoCo actuator index of the faulty actuator."""
  return module_actuators(robot)[fault.module - 1][fault.actuator]


def apply(spec: mujoco.MjSpec, robot) -> None:
  """Scales the gain of every faulty actuator of ``robot`` in its freshly built ``spec``."""
  for fault in robot.faults:
    actuator = spec.actuators[actuator_index(robot, fault)]
    actuator.gainprm[0] = actuator.gainprm[0] * fault.gain


def describe(robot, fault: Fault) -> dict:
  """The fault as a result record holds it: its fields, text form and MuJoCo actuator name."""
  name = robot.build_spec().actuators[actuator_index(robot, fault)].name
  return {
    "module": fault.module,
    "actuator": fault.actuator,
    "gain": fault.gain,
    "text": str(fault),
    "actuator_name": name,
    "punctured": fault.punctured,
  }
