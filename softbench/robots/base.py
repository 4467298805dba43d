"""What every softbench robot shares: a frozen spec that builds its MJCF, and its action map.

A robot's action is a vector in [-1, 1]; each MuJoCo actuator's control is a piecewise-linear
function of one action entry, given by its values at -1, 0 and +1. The map is written into the
MJCF as ``<custom><numeric name="action_map">`` so that an exported model file is enough to drive
the robot (``softbench.robots.physics.SoftArmPhysics`` reads it back).
"""

import abc
import dataclasses
import functools
import hashlib
import math

import mujoco
import numpy as np

from softbench.robots import faults as fault_model
from softbench.robots import payload as payload_model
from softbench.robots import versions

ACTION_MAP_NAME = "action_map"
XML_CACHE_SIZE = 16  # Robots whose MJCF each process keeps (under 0.5 MB each up to 10 modules).
MODULE_LENGTH_RANGE = (0.005, 1.0)  # (m) Module lengths an arm accepts: a typo such as 80 for
# 80 mm, or 1e-6, is refused rather than built (MuJoCo fails below about 1e-5 m).


@dataclasses.dataclass(frozen=True)
class ActuatorMap:
  """Control of one actuator as a function of action entry ``action_index``.

  ``ctrl = interp(a, [-1, 0, 1], [at_minus_one, at_zero, at_plus_one])``.
  """

  action_index: int
  at_minus_one: float
  at_zero: float
  at_plus_one: float


def action_to_ctrl(action_map: np.ndarray, action: np.ndarray) -> np.ndarray:
  """Maps actions (..., action_dim) to controls (..., num_actuators).

  Args:
    action_map: (num_actuators, 4) rows of (action index, ctrl at -1, at 0, at +1).
    action: Actions in [-1, 1]; any leading batch shape.
  """
  index = action_map[:, 0].astype(int)
  a = np.asarray(action, dtype=float)[..., index]
  below = action_map[:, 2] + a * (action_map[:, 2] - action_map[:, 1])
  above = action_map[:, 2] + a * (action_map[:, 3] - action_map[:, 2])
  return np.where(a < 0, below, above)


def checked_actions(actions, shape: tuple[int, ...], name: str = "action") -> np.ndarray:
  """``actions`` as floats of ``shape``, clipped to [-1, 1] within rounding.

  Raises:
    ValueError: not real numbers (bool, complex, text), another shape, or an entry that is NaN,
      infinite or outside [-1, 1] (one line, naming ``name``).
  """
  given = np.asarray(actions)
  if given.dtype.kind not in "iuf":  # Casting would drop an imaginary part or read True as 1.
    raise ValueError(f"{name} must hold real numbers, got an array of {given.dtype}")
  values = given.astype(float)
  if values.shape != tuple(shape):
    raise ValueError(f"{name} must have shape {tuple(shape)}, got {values.shape}")
  if not np.all(np.isfinite(values)):
    raise ValueError(f"{name} contains NaN or infinite values: {values.tolist()}")
  if np.any(np.abs(values) > 1.0 + 1e-9):
    raise ValueError(f"{name} entries must lie in [-1, 1], got {values.tolist()}")
  return np.clip(values, -1.0, 1.0)


class SoftArm(abc.ABC):
  """Base of the frozen spec dataclasses of every robot family.

  Every family has a ``faults`` field: a tuple of ``softbench.robots.faults.Fault`` (empty for a
  healthy robot), applied to the actuators' gains when the MJCF is built, and a ``payload``
  field: the mass at its tip (kg, ``softbench.robots.payload``; 0 for none).
  """

  faults: tuple[fault_model.Fault, ...] = ()
  payload: float = 0.0

  @property
  @abc.abstractmethod
  def name(self) -> str:
    """Registry name, e.g. ``tendon-3``."""

  @property
  @abc.abstractmethod
  def module_lengths(self) -> tuple[float, ...]:
    """Rest length of each module (m)."""

  @property
  @abc.abstractmethod
  def actuators_per_module(self) -> tuple[int, ...]:
    """Number of action entries of each module."""

  @property
  @abc.abstractmethod
  def control_timestep(self) -> float:
    """Time between two actions (s)."""

  @abc.abstractmethod
  def actuator_maps(self) -> list[ActuatorMap]:
    """One entry per MuJoCo actuator, in actuator order."""

  @abc.abstractmethod
  def _build(self, spec: mujoco.MjSpec) -> None:
    """Adds the robot's options, assets, bodies, tendons and actuators to an empty spec."""

  @abc.abstractmethod
  def mirror_action(self, action: np.ndarray) -> np.ndarray:
    """The action whose poses are the mirror images, under ``mirror_matrix``, of ``action``'s."""

  @abc.abstractmethod
  def bend_action_pattern(self, module: int) -> np.ndarray:
    """The module's own action entries that bend it fully towards world +x."""

  @abc.abstractmethod
  def bend_basis(self, module: int) -> np.ndarray:
    """(2, entries) the module's own action entries per unit of bending towards world +x (row
    0) and +y (row 1); ``planar_action`` combines them linearly."""

  @property
  @abc.abstractmethod
  def mirror_matrix(self) -> np.ndarray:
    """A 3x3 reflection or rotation of world coordinates that maps the robot onto itself."""

  @property
  def num_modules(self) -> int:
    return len(self.module_lengths)

  @property
  def length(self) -> float:
    """Rest length of the whole arm (m)."""
    return float(sum(self.module_lengths))

  @property
  def action_dim(self) -> int:
    return int(sum(self.actuators_per_module))

  def module_action_slices(self) -> list[slice]:
    """The slice of the action vector that belongs to each module."""
    ends = np.cumsum(self.actuators_per_module)
    return [slice(int(end - size), int(end)) for end, size in zip(ends, self.actuators_per_module)]

  def planar_action(self, points: np.ndarray) -> np.ndarray:
    """Actions (..., action_dim) that bend every module alike towards the planar actuation
    points (..., 2), i.e. ``x * bend_basis[0] + y * bend_basis[1]``, clipped to [-1, 1]."""
    points = np.asarray(points, dtype=float)
    action = np.concatenate(
      [points @ self.bend_basis(k) for k in range(1, self.num_modules + 1)], axis=-1
    )
    return np.clip(action, -1.0, 1.0)

  def action_map(self) -> np.ndarray:
    """(num_actuators, 4) rows of (action index, ctrl at -1, at 0, at +1), as
    ``action_to_ctrl`` takes them."""
    return np.array([dataclasses.astuple(m) for m in self.actuator_maps()], dtype=float)

  def action_to_ctrl(self, action: np.ndarray) -> np.ndarray:
    """Controls of every actuator for actions (..., action_dim) in [-1, 1]."""
    return action_to_ctrl(self.action_map(), action)

  def refined(self, factor: int) -> "SoftArm":
    """The same robot with ``factor`` times more segments and a time step ``factor`` times
    shorter, to measure discretisation error."""
    return dataclasses.replace(
      self, segments_per_module=self.segments_per_module * factor, timestep=self.timestep / factor
    )

  def with_faults(self, faults) -> "SoftArm":
    """The same robot with ``faults`` (an iterable of ``Fault``) instead of its own; raises a
    one-line ValueError for a fault that names no actuator of this robot."""
    return dataclasses.replace(self, faults=tuple(faults))

  def without_faults(self) -> "SoftArm":
    """The robot as designed (healthy)."""
    return self.with_faults(()) if self.faults else self

  def build_spec(self) -> mujoco.MjSpec:
    """A fresh ``MjSpec`` of this robot, ready to compile or export."""
    spec = mujoco.MjSpec()
    spec.modelname = self.name
    spec.compiler.degree = False
    self._build(spec)
    fault_model.apply(spec, self)
    payload_model.apply(spec, self)
    spec.add_numeric(name=ACTION_MAP_NAME, data=self.action_map().ravel().tolist())
    return spec

  def to_xml(self) -> str:
    """The robot's MJCF, generated once per process for equal robots (frozen specs): every
    environment, reference and cache key asks for it, and generating it takes 10 to 200 ms."""
    return _generated_xml(self)

  def physics_sha256(self) -> str:
    """The sha256 that cache keys (datasets, references, checkpoints) name the robot's physics
    by: of its MJCF, with the physics version after v0 (``softbench.robots.versions``), so that a
    robot whose MJCF is the same on two versions (the pneumatic arm) keys apart on each, while
    the keys made on v0 still hold there."""
    version = versions.current().name
    text = self.to_xml() + ("" if version == versions.FIRST else f"\n<!-- physics {version} -->")
    return hashlib.sha256(text.encode()).hexdigest()

  def compile(self) -> mujoco.MjModel:
    """The model exactly as its exported MJCF loads (the XML rounds numbers to 6 digits, so
    compiling the spec directly would give a slightly different model)."""
    return mujoco.MjModel.from_xml_string(self.to_xml())

  def mass(self, model: mujoco.MjModel | None = None) -> float:
    """Total mass of the moving arm (kg)."""
    model = model if model is not None else self.compile()
    base_body = model.body("base").id
    return float(model.body_subtreemass[base_body] - model.body_mass[base_body])


@functools.lru_cache(maxsize=XML_CACHE_SIZE)
def _generated_xml(robot: SoftArm) -> str:
  spec = robot.build_spec()
  spec.compile()
  return spec.to_xml()


def check_positive(name: str, value: float) -> None:
  if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
    raise ValueError(f"{name} must be a positive number, got {value!r}")


def check_module_length(value: float) -> None:
  """Raises a one-line ValueError unless ``value`` lies in ``MODULE_LENGTH_RANGE``."""
  check_positive("module_length", value)
  low, high = MODULE_LENGTH_RANGE
  if not low <= value <= high:
    raise ValueError(f"module_length must lie between {low:g} and {high:g} m, got {value!r}")
