"""``tendon-N``: a modular tendon-driven soft arm, cables crossing the proximal modules (SPEC 2.1).

N modules of 50 mm hang from a fixed base under gravity. The backbone is a silicone rod cut into
rigid segments whose elasticity bends with E·I and twists with G·J: plugin-free (``backbone="rod"``,
physics v1: ball-joint springs and a torsion actuator per joint, ``softbench.robots.chain``) or from
MuJoCo 3's ``mujoco.elasticity.cable`` plugin (``backbone="cable"``, physics v0, as
``<composite type="cable">`` expands); the two give the same forces to rounding. Each module has
four cables at 90 degrees, routed as spatial tendons through holes near both ends of every segment
(a channel along the rod) and anchored at the module's tip; a cable of module k passes through all
of modules 1..k-1, closer to the axis, so actuating a distal module also bends the proximal ones.

Action: two values per module in [-1, 1]. Value a of axis x pulls the +x cable with tension
max(0, a)·Tmax and the -x cable with max(0, -a)·Tmax (the paper's antagonistic convention);
likewise for y.

``CableDrivenArm`` is what every tendon family shares (backbone, material, cables, actuation);
a family decides only where each cable runs (``cable_route``). ``tendon_local`` holds the
module-local family, ``tendon-local-N``.
"""

import abc
import dataclasses
import math
from typing import ClassVar

import mujoco
import numpy as np

from softbench.robots import base
from softbench.robots import catalogue
from softbench.robots import chain
from softbench.robots import faults as fault_model
from softbench.robots import payload as payload_model
from softbench.robots import versions

MODULE_LENGTH = catalogue.TENDON_MODULE_LENGTH  # (m)
MAX_MODULES = catalogue.MAX_MODULES  # Largest N that builds; N = 1 .. 5 are the benchmark ones.
BACKBONES = ("rod", "cable")  # versions.PhysicsVersion.backbone of physics v1 and v0.
# Cables, as (name, angle around the arm in degrees, action axis, sign of the action that pulls it).
_CABLES = (
  ("xpos", 0.0, 0, +1),
  ("ypos", 90.0, 1, +1),
  ("xneg", 180.0, 0, -1),
  ("yneg", 270.0, 1, -1),
)
_MODULE_RGBA = (
  (0.90, 0.35, 0.25, 1),
  (0.95, 0.70, 0.20, 1),
  (0.35, 0.70, 0.35, 1),
  (0.25, 0.55, 0.85, 1),
  (0.55, 0.40, 0.80, 1),
)


@dataclasses.dataclass(frozen=True)
class CableDrivenArm(base.SoftArm):
  """Frozen spec of a tendon-driven arm of any family; every field has SI units.

  Attributes:
    num_modules: Number of 50 mm modules, 1 to 10.
    module_length: Rest length of one module (m).
    segments_per_module: Rigid segments per module (discretisation of the rod).
    hole_inset: Distance of a cable hole from the nearest joint, as a fraction of the segment
      length. The holes on the concave side of a joint meet when it bends by
      2·atan(hole_inset · segment length / cable_offset), 16 degrees per joint or about 114
      degrees per module by default: a bending limit, like spacer disks touching, that holds at
      every discretisation because the inset scales with the segment.
    radius: Backbone radius (m).
    youngs_modulus: Young's modulus E of the silicone backbone (Pa).
    poisson_ratio: Poisson's ratio; the torsion modulus is E / (2 (1 + nu)).
    density: Backbone density (kg/m³), silicone rubber.
    cable_offset: Distance of a cable from the backbone axis inside its own module (m).
    max_tension: Tmax, the cable tension at action ±1 (N).
    damping: Rotational damping of every segment joint (N·m·s/rad).
    medium_viscosity: Viscosity of the surrounding medium (Pa·s), MuJoCo's Stokes drag on every
      segment. It damps motion in absolute terms, as PyElastica's linear damper does in the
      paper's simulator, so that long arms settle within one control period; joint damping alone
      damps only relative motion and left tendon-5 swinging for seconds.
    armature: Added inertia of every joint DOF (kg·m²).
    backbone: ``"rod"`` (plugin-free, physics v1) or ``"cable"`` (MuJoCo 3's cable plugin,
      physics v0); by default the backbone of the installed physics version.
    timestep: Physics time step (s).
    control_period: Time between two actions (s).
    faults: Faulty cables (``softbench.robots.faults``; actuator i of a module is cable
      ``xpos``, ``ypos``, ``xneg``, ``yneg`` for i = 0 .. 3); empty for a healthy arm.
    payload: Mass carried at the tip (kg; ``softbench.robots.payload``); 0 for none.
  """

  num_modules: int = 3
  module_length: float = MODULE_LENGTH
  segments_per_module: int = 7
  hole_inset: float = 0.12
  radius: float = 0.005
  youngs_modulus: float = 1.0e6
  poisson_ratio: float = 0.5
  density: float = 1100.0
  cable_offset: float = 0.006
  max_tension: float = 2.58  # Bends tendon-1 by 89.8 deg (bisection on measure.bend_angle).
  damping: float = 2.0e-3
  medium_viscosity: float = 0.1
  armature: float = 1.0e-5
  backbone: str = versions.current().backbone
  timestep: float = 4.0e-3
  control_period: float = 1.0
  faults: tuple[fault_model.Fault, ...] = ()
  payload: float = 0.0

  FAMILY: ClassVar[str]  # Registry names are FAMILY-N.
  _POSITIVE_FIELDS: ClassVar[tuple[str, ...]] = ()  # A family's own fields that must be > 0.

  def __post_init__(self):
    if (
      isinstance(self.num_modules, bool)
      or not isinstance(self.num_modules, int)
      or not 1 <= self.num_modules <= MAX_MODULES
    ):
      raise ValueError(
        f"{self.FAMILY} arms have 1 to {MAX_MODULES} modules, got {self.num_modules!r}"
      )
    if not isinstance(self.segments_per_module, int) or self.segments_per_module < 1:
      raise ValueError(
        f"segments_per_module must be a positive integer, got {self.segments_per_module!r}"
      )
    if not 0 < self.hole_inset < 0.5:
      raise ValueError(f"hole_inset must lie strictly between 0 and 0.5, got {self.hole_inset!r}")
    for field in (
      "radius",
      "youngs_modulus",
      "density",
      "cable_offset",
      "max_tension",
      "timestep",
      "control_period",
      *self._POSITIVE_FIELDS,
    ):
      base.check_positive(field, getattr(self, field))
    base.check_module_length(self.module_length)
    for field in ("damping", "medium_viscosity", "armature"):
      if not getattr(self, field) >= 0:
        raise ValueError(f"{field} must be non-negative, got {getattr(self, field)!r}")
    if not 0 <= self.poisson_ratio <= 0.5:
      raise ValueError(f"poisson_ratio must lie in [0, 0.5], got {self.poisson_ratio!r}")
    if self.backbone not in BACKBONES:
      raise ValueError(f"unknown backbone {self.backbone!r}; choose one of {', '.join(BACKBONES)}")
    if self.backbone == "cable" and not versions.cable_plugin_available():
      raise ValueError(versions.cable_plugin_missing())
    fault_model.check(self, self.faults)
    payload_model.check(self.payload)

  @classmethod
  def from_name(cls, name: str, **overrides) -> "CableDrivenArm":
    """``TendonArm.from_name('tendon-3')``; raises ValueError for a malformed name."""
    num_modules = catalogue.family_named(cls.FAMILY).num_modules(name)
    if "num_modules" in overrides:
      raise ValueError(f"{name!r} names its number of modules; drop num_modules")
    return cls(num_modules=num_modules, **overrides)

  @property
  def name(self) -> str:
    return f"{self.FAMILY}-{self.num_modules}"

  @property
  def module_lengths(self) -> tuple[float, ...]:
    return (self.module_length,) * self.num_modules

  @property
  def actuators_per_module(self) -> tuple[int, ...]:
    return (2,) * self.num_modules

  @property
  def control_timestep(self) -> float:
    return self.control_period

  @property
  def bending_stiffness(self) -> float:
    """E·I of the backbone (N·m²)."""
    return self.youngs_modulus * math.pi * self.radius**4 / 4

  @property
  def torsional_stiffness(self) -> float:
    """G·J of the backbone (N·m²): G = E / (2 (1 + nu)) and J = 2 I for a circular section."""
    return self.youngs_modulus / (2 * (1 + self.poisson_ratio)) * math.pi * self.radius**4 / 2

  @property
  def segment_length(self) -> float:
    return self.module_length / self.segments_per_module

  def actuator_maps(self) -> list[base.ActuatorMap]:
    maps = []
    for module in range(self.num_modules):
      for _, _, axis, sign in _CABLES:
        index = 2 * module + axis
        pulled_at_plus = self.max_tension if sign > 0 else 0.0
        pulled_at_minus = self.max_tension if sign < 0 else 0.0
        maps.append(base.ActuatorMap(index, pulled_at_minus, 0.0, pulled_at_plus))
    # The rod's torsion actuators (one per segment joint) follow the cables and take no control.
    torsion = self.num_modules * self.segments_per_module if self.backbone == "rod" else 0
    return maps + [base.ActuatorMap(0, 0.0, 0.0, 0.0)] * torsion

  def mirror_action(self, action: np.ndarray) -> np.ndarray:
    # Every cable has an opposite one: -a pulls the opposite cables, i.e. the arm turned by
    # 180 degrees about the vertical axis.
    return -np.asarray(action)

  @property
  def mirror_matrix(self) -> np.ndarray:
    return np.diag([-1.0, -1.0, 1.0])

  def bend_action_pattern(self, module: int) -> np.ndarray:
    return np.array([1.0, 0.0])  # Pull the +x cable with Tmax.

  def bend_basis(self, module: int) -> np.ndarray:
    return np.eye(2)  # Action entry 0 pulls the +x cable, entry 1 the +y cable.

  def _build(self, spec: mujoco.MjSpec) -> None:
    spec.option.timestep = self.timestep
    spec.option.viscosity = self.medium_viscosity
    # Euler integrates joint damping implicitly and the medium's drag explicitly, which is cheap;
    # implicitfast would differentiate the drag and ran 3x slower for the same stability.
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_EULER
    # A chain's mass matrix is dense whatever its length; dense Jacobians measured 25% faster.
    spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    geometry = chain.ChainGeometry(
      self.module_lengths, self.segments_per_module, self.radius, self.density
    )
    if self.backbone == "cable":
      spec.activate_plugin(chain.CABLE_PLUGIN)
      plugin = spec.add_plugin(
        name="backbone_elasticity", plugin_name=chain.CABLE_PLUGIN, active=True
      )
      torsion_modulus = self.youngs_modulus / (2 * (1 + self.poisson_ratio))
      plugin.config = {
        "twist": repr(torsion_modulus),
        "bend": repr(self.youngs_modulus),
        "vmax": "0",
      }
      joints = chain.SegmentJoints(0.0, ball_damping=self.damping, armature=self.armature)
    else:
      plugin = None
      joints = chain.SegmentJoints(
        self.bending_stiffness,
        ball_damping=self.damping,
        armature=self.armature,
        torsional_stiffness=self.torsional_stiffness,
      )
    base_body = spec.worldbody.add_body(name="base")
    base_body.add_geom(
      name="base_plate",
      type=mujoco.mjtGeom.mjGEOM_CYLINDER,
      size=(self.cable_offset * 2, 0.002, 0),
      pos=(0, 0, 0.002),
      rgba=(0.3, 0.3, 0.3, 1),
      contype=0,
      conaffinity=0,
    )
    rod = chain.add_chain(base_body, geometry, joints, _MODULE_RGBA, plugin)
    self._add_cables(spec, rod)
    chain.add_torsion_actuators(spec, rod)

  @abc.abstractmethod
  def cable_route(self, rod: chain.Chain, module: int) -> list[tuple[str, float, float]]:
    """Where each cable of ``module`` (1-based) is held on its way from the base of the arm or
    of its module to the module's tip, before its anchor: (site label, arc length (m), distance
    from the axis (m)) per hole, base first. The label, completed with the cable's name, names
    the site; cables of different modules that share a label share the hole."""

  def _add_cables(self, spec: mujoco.MjSpec, rod: chain.Chain) -> None:
    """Routes four cables per module along ``cable_route`` to the module's tip, where each is
    anchored at ``cable_offset``, and gives each cable a pulling motor."""
    angles = [angle for _, angle, _, _ in _CABLES]
    added = set()  # Holes are shared by every cable that passes them.
    for module in range(1, self.num_modules + 1):
      tip = rod.geometry.module_start(module + 1)
      rgba = chain.module_rgba(_MODULE_RGBA, module)
      route = self.cable_route(rod, module)
      for cable, (cable_name, *_) in enumerate(_CABLES):
        tendon = spec.add_tendon(name=f"module{module}_cable_{cable_name}", width=0.0005, rgba=rgba)
        for label, arc_length, offset in route:
          site = f"{label}_{cable_name}"
          if site not in added:
            added.add(site)
            rod.add_site(
              site,
              arc_length,
              chain.ring_offsets(offset, angles)[cable],
              size=(0.0006, 0, 0),
              rgba=(0.2, 0.2, 0.2, 1),
            )
          tendon.wrap_site(site)
        anchor = f"module{module}_anchor_{cable_name}"
        rod.add_site(
          anchor,
          tip,
          chain.ring_offsets(self.cable_offset, angles)[cable],
          size=(0.0009, 0, 0),
          rgba=(0.1, 0.1, 0.1, 1),
        )
        tendon.wrap_site(anchor)
        spec.add_actuator(
          name=f"module{module}_cable_{cable_name}",
          trntype=mujoco.mjtTrn.mjTRN_TENDON,
          target=tendon.name,
          gear=(-1, 0, 0, 0, 0, 0),  # Cables pull: positive control shortens the tendon.
          ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
          ctrlrange=(0, self.max_tension),
        )


@dataclasses.dataclass(frozen=True)
class TendonArm(CableDrivenArm):
  """``tendon-N``: every cable runs from the arm's base, through the proximal modules, to its
  module's tip (the fields of ``CableDrivenArm``, and one more).

  Attributes:
    pass_through_offset: Distance from the axis of the holes through which a cable crosses the
      proximal modules on its way to its own (m); closer to the axis than ``cable_offset`` so
      that a distal cable loads proximal modules with a third of the moment, not all of it.
  """

  pass_through_offset: float = 0.002

  FAMILY: ClassVar[str] = "tendon"
  _POSITIVE_FIELDS: ClassVar[tuple[str, ...]] = ("pass_through_offset",)

  def cable_route(self, rod: chain.Chain, module: int) -> list[tuple[str, float, float]]:
    """Through every hole of the channel from the base: at ``cable_offset`` inside the cable's
    own module (and all of module 1), at ``pass_through_offset`` in the proximal modules."""
    start, tip = rod.geometry.module_start(module), rod.geometry.module_start(module + 1)
    route = []
    for prefix, arc_length in rod.channel_holes(self.hole_inset, end=tip):
      own = arc_length >= start or module == 1
      route.append(
        (
          f"{prefix}_{'outer' if own else 'inner'}_hole",
          arc_length,
          self.cable_offset if own else self.pass_through_offset,
        )
      )
    return route
