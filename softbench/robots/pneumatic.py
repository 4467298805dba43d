"""``pneumatic-433``: a three-module arm of bellows actuators (SPEC 2.2, the paper's real robot).

Module 1 (at the base) has 4 bellows at 90 degrees, modules 2 and 3 have 3 bellows at 120
degrees. Each bellows is a spatial tendon from its module's base plate to its tip plate, driven by
a position actuator: a spring of stiffness ``bellows_stiffness`` whose rest length follows the
pressure, from 0.7x its characteristic length at -40 kPa to 1.2x at +90 kPa (the paper's measured
range). Action a in [-1, 1] maps to pressure piecewise linearly, a = -1 -> -40 kPa, 0 -> 0 kPa,
+1 -> +90 kPa, so zero action is zero pressure and the characteristic length. Combined bellows
bend the module in any direction and lengthen or shorten it; the modules' backbone is a chain
with ball and slide joints that holds the plates apart and resists twist.
"""

import dataclasses

import mujoco
import numpy as np

from softbench.robots import base
from softbench.robots import catalogue
from softbench.robots import chain
from softbench.robots import faults as fault_model
from softbench.robots import payload as payload_model

MODULE_LENGTH = catalogue.PNEUMATIC_MODULE_LENGTH  # (m)
BELLOWS_PER_MODULE = catalogue.PNEUMATIC_BELLOWS
MIN_PRESSURE, MAX_PRESSURE = -40.0, 90.0  # (kPa) Paper: "-40KPa" and "90 KPa".
MIN_LENGTH_RATIO, MAX_LENGTH_RATIO = 0.7, 1.2  # Paper: 70 % contraction, 120 % elongation.
_MODULE_RGBA = ((0.90, 0.35, 0.25, 1), (0.35, 0.70, 0.35, 1), (0.25, 0.55, 0.85, 1))


def pressure_to_length_ratio(pressure_kpa: np.ndarray) -> np.ndarray:
  """Bellows length over characteristic length, piecewise linear in pressure (kPa)."""
  return np.interp(
    pressure_kpa, [MIN_PRESSURE, 0.0, MAX_PRESSURE], [MIN_LENGTH_RATIO, 1.0, MAX_LENGTH_RATIO]
  )


def action_to_pressure(action: np.ndarray) -> np.ndarray:
  """Pressure (kPa) commanded by actions in [-1, 1]."""
  return np.interp(action, [-1.0, 0.0, 1.0], [MIN_PRESSURE, 0.0, MAX_PRESSURE])


@dataclasses.dataclass(frozen=True)
class PneumaticArm(base.SoftArm):
  """Frozen spec of the three-module bellows arm; every field has SI units.

  Attributes:
    module_length: Characteristic (zero-pressure) length of each module's bellows (m).
    bellows_per_module: Number of bellows of each module, evenly spaced around the axis.
    bellows_offset: Distance of every bellows axis from the module axis (m); 22 mm lets four
      30 mm bellows sit side by side.
    bellows_radius: Outer radius of a bellows (m), for drawing; the paper's 30 mm diameter.
    bellows_stiffness: Axial stiffness of one bellows about its pressure-set rest length (N/m).
    bellows_damping: Axial damping of one bellows (N·s/m).
    module_mass: Mass of one module, bellows and plates (kg).
    segments_per_module: Rigid segments of each module's backbone chain.
    backbone_radius: Radius of the backbone cylinders (m), which carry the module mass.
    backbone_bending_stiffness: E·I of the backbone (N·m²): the plates' resistance to bending and
      twist beyond what the bellows give.
    backbone_axial_stiffness: Axial stiffness of one module's backbone (N/m). Its
      ``segments_per_module`` slide joints act in series, so each gets this times their count,
      and the module's stiffness does not depend on the discretisation.
    backbone_axial_damping: Axial damping of one module's backbone (N·s/m), shared among its
      slide joints in series the same way.
    joint_damping: Damping of the backbone's ball joints (N·m·s/rad).
    armature: Added inertia of every joint DOF (kg·m² or kg).
    timestep: Physics time step (s).
    control_period: Time between two actions (s); the paper actuates the robot at 5 Hz.
    faults: Faulty bellows (``softbench.robots.faults``; actuator i of a module is its bellows
      i + 1); empty for a healthy arm.
    payload: Mass carried at the tip (kg; ``softbench.robots.payload``); 0 for none.
  """

  module_length: float = MODULE_LENGTH
  bellows_per_module: tuple[int, ...] = BELLOWS_PER_MODULE
  bellows_offset: float = 0.022
  bellows_radius: float = 0.015
  bellows_stiffness: float = 1000.0
  bellows_damping: float = 10.0
  module_mass: float = 0.08
  segments_per_module: int = 4
  backbone_radius: float = 0.008
  backbone_bending_stiffness: float = 0.02
  backbone_axial_stiffness: float = 12.5
  backbone_axial_damping: float = 0.5
  joint_damping: float = 0.05
  armature: float = 1.0e-5
  timestep: float = 1.0e-3
  control_period: float = 0.2
  faults: tuple[fault_model.Fault, ...] = ()
  payload: float = 0.0

  def __post_init__(self):
    for field in (
      "bellows_offset",
      "bellows_radius",
      "bellows_stiffness",
      "module_mass",
      "backbone_radius",
      "backbone_bending_stiffness",
      "backbone_axial_stiffness",
      "timestep",
      "control_period",
    ):
      base.check_positive(field, getattr(self, field))
    base.check_module_length(self.module_length)
    if not self.bellows_per_module or any(
      not isinstance(n, int) or n < 3 for n in self.bellows_per_module
    ):
      raise ValueError(
        f"every module needs at least 3 bellows for omnidirectional bending, got "
        f"{self.bellows_per_module!r}"
      )
    if not isinstance(self.segments_per_module, int) or self.segments_per_module < 1:
      raise ValueError(
        f"segments_per_module must be a positive integer, got {self.segments_per_module!r}"
      )
    fault_model.check(self, self.faults)
    payload_model.check(self.payload)

  @property
  def name(self) -> str:
    return "pneumatic-" + "".join(str(n) for n in self.bellows_per_module)

  @property
  def module_lengths(self) -> tuple[float, ...]:
    return (self.module_length,) * len(self.bellows_per_module)

  @property
  def actuators_per_module(self) -> tuple[int, ...]:
    return tuple(self.bellows_per_module)

  @property
  def control_timestep(self) -> float:
    return self.control_period

  def bellows_angles(self, module: int) -> list[float]:
    """Angles (deg) of a module's bellows around the axis, world frame at rest."""
    count = self.bellows_per_module[module - 1]
    return [360.0 * i / count for i in range(count)]

  def actuator_maps(self) -> list[base.ActuatorMap]:
    # Controls are length changes (m) from the characteristic length, so that the default
    # control 0 of a fresh simulation is zero pressure.
    ratios = pressure_to_length_ratio(action_to_pressure(np.array([-1.0, 0.0, 1.0])))
    changes = (ratios - 1.0) * self.module_length
    return [base.ActuatorMap(index, *changes) for index in range(self.action_dim)]

  def mirror_action(self, action: np.ndarray) -> np.ndarray:
    # Reflection y -> -y maps a bellows at angle phi onto the one at -phi.
    action = np.asarray(action)
    permutation = []
    for module, actions in enumerate(self.module_action_slices(), start=1):
      count = self.bellows_per_module[module - 1]
      permutation += [actions.start + (-i) % count for i in range(count)]
    return action[..., permutation]

  @property
  def mirror_matrix(self) -> np.ndarray:
    return np.diag([1.0, -1.0, 1.0])

  def bend_action_pattern(self, module: int) -> np.ndarray:
    # Empty the bellows on the +x side and fill those on the -x side.
    cosines = np.cos(np.deg2rad(self.bellows_angles(module)))
    return -np.sign(np.round(cosines, 9))

  def bend_basis(self, module: int) -> np.ndarray:
    # Bending towards a direction empties the bellows on that side and fills the opposite ones.
    angles = np.deg2rad(self.bellows_angles(module))
    return -np.stack([np.cos(angles), np.sin(angles)])

  def _build(self, spec: mujoco.MjSpec) -> None:
    spec.option.timestep = self.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    volume = np.pi * self.backbone_radius**2 * self.module_length
    geometry = chain.ChainGeometry(
      self.module_lengths, self.segments_per_module, self.backbone_radius, self.module_mass / volume
    )
    joints = chain.SegmentJoints(
      bending_stiffness=self.backbone_bending_stiffness,
      ball_damping=self.joint_damping,
      armature=self.armature,
      slide_stiffness=self.backbone_axial_stiffness * self.segments_per_module,
      slide_damping=self.backbone_axial_damping * self.segments_per_module,
    )
    base_body = spec.worldbody.add_body(name="base")
    base_body.add_geom(
      name="base_plate",
      type=mujoco.mjtGeom.mjGEOM_CYLINDER,
      size=(self.bellows_offset + self.bellows_radius, 0.003, 0),
      pos=(0, 0, 0.003),
      rgba=(0.3, 0.3, 0.3, 1),
      contype=0,
      conaffinity=0,
    )
    rod = chain.add_chain(base_body, geometry, joints, _MODULE_RGBA, cable_plugin=None)
    self._add_bellows(spec, rod)

  def _add_bellows(self, spec: mujoco.MjSpec, rod: chain.Chain) -> None:
    """Each bellows: a tendon through sites at every segment midpoint of its module, from the
    module's base plate to its tip plate, driven by a position actuator on its length whose
    control is the change of rest length: force = k (L0 + ctrl - length) - c · velocity."""
    lengths = (
      [m.at_minus_one for m in self.actuator_maps()],
      [m.at_plus_one for m in self.actuator_maps()],
    )
    index = 0
    for module in range(1, self.num_modules + 1):
      start = rod.geometry.module_start(module)
      spacing = rod.geometry.segment_length(module)
      offsets = chain.ring_offsets(self.bellows_offset, self.bellows_angles(module))
      rgba = chain.module_rgba(_MODULE_RGBA, module)
      for bellows, offset in enumerate(offsets, start=1):
        name = f"module{module}_bellows{bellows}"
        tendon = spec.add_tendon(name=name, width=self.bellows_radius * 0.5, rgba=(*rgba[:3], 0.6))
        for point in range(self.segments_per_module + 1):
          site = rod.add_site(
            f"{name}_site{point}",
            start + point * spacing,
            offset,
            size=(0.002, 0, 0),
            rgba=(0.2, 0.2, 0.2, 1),
          )
          tendon.wrap_site(site.name)
        spec.add_actuator(
          name=name,
          trntype=mujoco.mjtTrn.mjTRN_TENDON,
          target=name,
          gaintype=mujoco.mjtGain.mjGAIN_FIXED,
          biastype=mujoco.mjtBias.mjBIAS_AFFINE,
          gainprm=[self.bellows_stiffness] + [0] * 9,
          biasprm=[
            self.bellows_stiffness * self.module_length,
            -self.bellows_stiffness,
            -self.bellows_damping,
          ]
          + [0] * 7,
          ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
          ctrlrange=(lengths[0][index], lengths[1][index]),
        )
        index += 1
