"""A hanging chain of rigid segments: the backbone shared by every soft arm in softbench.

The rod is discretised in a staggered way. Joints sit at arc lengths (i - 1/2)·l of every module
(l its segment length); each joint stands for the rod between two segment midpoints, and a rigid
body spans from one joint to the next. Module boundaries therefore fall at body
midpoints, where a body's orientation equals the rod's tangent to second order, and every joint's
stiffness is E·I over the distance between the origins of the two bodies it joins (the cable
plugin's own rule) with that distance equal to l everywhere. Tip positions converge with the
square of the segment length and orientations at module tips are second-order accurate.

Every body has its local x-axis along the arm (the convention of MuJoCo's cable plugin, which
applies torsion about local x). A clamp body, welded to the base, holds the rod's first half
segment. Each module's tip carries a site ``module{k}_tip`` whose z-axis is the arm axis.

Bending and twisting stiffness are set separately, with elements that MuJoCo 4, MJX and MuJoCo
Warp all support. MuJoCo's cable plugin (removed in MuJoCo 4) puts the generalised force
f = -Rᵀ K ω / l on each ball joint, with ω the rotation vector of the joint, R its rotation,
K = diag(G·J, E·I, E·I) and l the segment length. Since Rᵀ ω = ω, that is
-(E·I / l) ω + ((E·I - G·J) / l) ω_x Rᵀ e_x: the ball joint's own spring (stiffness E·I / l,
isotropic, exactly MuJoCo's ball spring) plus a torque about the parent segment's x-axis that grows
with the twist component of ω. MuJoCo's ``jointinparent`` transmission gives exactly that on a
ball joint (length ω·e_x, moment Rᵀ e_x), so each joint gets a torsion actuator with no control
(gain 0) and an affine bias of (E·I - G·J) / l times its length. Together they reproduce the
plugin's law to rounding, including its non-conservative second-order term, which no arrangement
of joint springs (a twist hinge in series with a ball, or three hinges) can: those were measured
up to 1.1 mm (series) and 10.8 mm (hinges) away from the plugin's equilibria on tendon-3.
"""

import dataclasses
import math
from typing import Sequence

import mujoco
import numpy as np

# R_y(+90 deg), as (w, x, y, z): takes a frame's x-axis onto its z-axis, and, used as the clamp's
# orientation, points the arm's x-axis to world -z so that the arm hangs down.
X_TO_Z_QUAT = (math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0)
CABLE_PLUGIN = "mujoco.elasticity.cable"
CLAMP = "clamp"


@dataclasses.dataclass(frozen=True)
class SegmentJoints:
  """How consecutive segments are joined.

  Attributes:
    bending_stiffness: E·I of the rod (N·m²) that the ball joints reproduce, each with rotational
      stiffness E·I / (distance between the origins of the two bodies it joins); 0 when the cable
      plugin supplies the elasticity.
    torsional_stiffness: G·J of the rod (N·m²), or None for a rod that twists as stiffly as it
      bends (a plain ball spring). Otherwise every joint also gets a torsion actuator (see the
      module's docstring; ``add_torsion_actuators``).
    ball_damping: Rotational damping (N·m·s/rad).
    armature: Added inertia of every joint DOF (kg·m²); it tames the highest frequencies of short
      segments so that a larger time step stays stable, and leaves equilibria unchanged.
    slide_stiffness: Axial stiffness (N/m) of an extra slide joint along the arm, or None for an
      inextensible rod.
    slide_damping: Axial damping (N·s/m).
  """

  bending_stiffness: float
  ball_damping: float
  armature: float
  torsional_stiffness: float | None = None
  slide_stiffness: float | None = None
  slide_damping: float = 0.0


@dataclasses.dataclass(frozen=True)
class ChainGeometry:
  """Shape and material of the rod.

  Attributes:
    module_lengths: Rest length of each module (m), base to tip.
    segments_per_module: Number of joints (and segments) per module.
    radius: Radius of the rod (m).
    density: Material density (kg/m³).
  """

  module_lengths: tuple[float, ...]
  segments_per_module: int
  radius: float
  density: float

  @property
  def num_modules(self) -> int:
    return len(self.module_lengths)

  def segment_length(self, module: int) -> float:
    return self.module_lengths[module - 1] / self.segments_per_module

  def module_start(self, module: int) -> float:
    """Arc length (m) of the proximal end of a module."""
    return float(sum(self.module_lengths[: module - 1]))

  def joint_arc_lengths(self) -> list[float]:
    """Arc length (m) of every joint, in chain order."""
    return [
      self.module_start(k) + (i - 0.5) * self.segment_length(k)
      for k in range(1, self.num_modules + 1)
      for i in range(1, self.segments_per_module + 1)
    ]


def segment_name(module: int, segment: int) -> str:
  """Name of segment ``segment`` (1-based) of module ``module`` (1-based)."""
  return f"module{module}_segment{segment}"


def module_rgba(palette: Sequence[Sequence[float]], module: int) -> Sequence[float]:
  """The colour of module ``module`` (1-based), cycling through ``palette``."""
  return palette[(module - 1) % len(palette)]


def tip_site_name(module: int) -> str:
  return f"module{module}_tip"


def torsion_actuator_name(segment: str) -> str:
  """Name of the torsion actuator of the joint that carries ``segment``."""
  return f"{segment}_torsion"


class Chain:
  """The bodies of a built chain, and where along the rod each one starts."""

  def __init__(
    self,
    bodies: list[mujoco.MjsBody],
    origins: list[float],
    geometry: ChainGeometry,
    joints: SegmentJoints,
  ):
    self.bodies = bodies  # The clamp first, then every segment.
    self.origins = origins  # Rest arc length (m) of each body's origin.
    self.geometry = geometry
    self.joints = joints

  def locate(self, arc_length: float) -> tuple[mujoco.MjsBody, float]:
    """The body holding the rod at ``arc_length`` and the local x of that point (m)."""
    index = int(np.searchsorted(self.origins, arc_length + 1e-12, side="right")) - 1
    index = max(index, 0)
    return self.bodies[index], arc_length - self.origins[index]

  def channel_holes(
    self, inset_fraction: float, start: float = 0.0, end: float = math.inf
  ) -> list[tuple[str, float]]:
    """Where a tendon running in a channel along the rod is held, as (label, arc length) with
    ``start <= arc length < end``: near both ends of every body, ``inset_fraction`` of a segment
    from each joint, so the short stretch crossing a joint passes it at the channel's offset and
    the moment the joint sees converges to tension x offset as segments shrink."""
    joints = self.geometry.joint_arc_lengths()
    n = self.geometry.segments_per_module
    insets = [inset_fraction * self.geometry.segment_length(i // n + 1) for i in range(len(joints))]
    holes = [(f"{self.bodies[0].name}_distal", joints[0] - insets[0])]
    for index in range(len(joints)):
      name = self.bodies[index + 1].name
      holes.append((f"{name}_proximal", joints[index] + insets[index]))
      if index + 1 < len(joints):
        holes.append((f"{name}_distal", joints[index + 1] - insets[index + 1]))
    return [(label, s) for label, s in holes if start <= s < end]

  def add_site(
    self, name: str, arc_length: float, offset: Sequence[float] = (0.0, 0.0), **attributes
  ) -> mujoco.MjsSite:
    """Adds a site at ``arc_length`` along the rod, ``offset`` = (local y, local z) off its axis."""
    body, x = self.locate(arc_length)
    return body.add_site(name=name, pos=(x, offset[0], offset[1]), **attributes)


def add_chain(
  parent: mujoco.MjsBody,
  geometry: ChainGeometry,
  joints: SegmentJoints,
  rgba: Sequence[Sequence[float]],
  cable_plugin: mujoco.MjsPlugin | None = None,
) -> Chain:
  """Adds the clamp and the segments below ``parent``, and a tip site per module.

  With ``cable_plugin`` each body carries that plugin instance, exactly as
  ``<composite type="cable">`` expands.
  """
  joint_s = geometry.joint_arc_lengths()
  ends = joint_s[1:] + [sum(geometry.module_lengths)]
  first_length = geometry.segment_length(1)
  # The clamp's origin lies half a segment above the base, so that the first joint's distance to
  # it is a full segment; its geometry covers the rod's first half segment, below the base.
  clamp_origin = -first_length / 2
  body = parent.add_body(name=CLAMP, pos=(0, 0, -clamp_origin), quat=X_TO_Z_QUAT)
  _add_rod_geom(
    body,
    f"{CLAMP}_geom",
    0.0 - clamp_origin,
    joint_s[0] - clamp_origin,
    geometry,
    (0.3, 0.3, 0.3, 1),
  )
  if cable_plugin is not None:
    body.plugin = cable_plugin
  bodies, origins = [body], [clamp_origin]
  n = geometry.segments_per_module
  for index, (start, end) in enumerate(zip(joint_s, ends)):
    module, segment = index // n + 1, index % n + 1
    name = segment_name(module, segment)
    body = body.add_body(name=name, pos=(start - origins[-1], 0, 0))
    _add_joints(body, name, joints, start - origins[-1])
    _add_rod_geom(body, f"{name}_geom", 0.0, end - start, geometry, module_rgba(rgba, module))
    if cable_plugin is not None:
      body.plugin = cable_plugin
    bodies.append(body)
    origins.append(start)
  built = Chain(bodies, origins, geometry, joints)
  for module in range(1, geometry.num_modules + 1):
    built.add_site(
      tip_site_name(module),
      geometry.module_start(module) + geometry.module_lengths[module - 1],
      quat=X_TO_Z_QUAT,
      size=(geometry.radius * 0.6, 0, 0),
      rgba=(1, 1, 1, 1),
    )
  return built


def add_torsion_actuators(spec: mujoco.MjSpec, rod: Chain) -> None:
  """Gives every ball joint of ``rod`` the torsion actuator that makes its twisting stiffness
  G·J / l while its spring bends with E·I / l (see the module's docstring); none for a rod whose
  ``torsional_stiffness`` is None.

  Add them after the robot's own actuators, whose indices the action map and faults count.
  """
  joints = rod.joints
  if joints.torsional_stiffness is None:
    return
  for body, origin, previous in zip(rod.bodies[1:], rod.origins[1:], rod.origins[:-1]):
    spacing = origin - previous
    softening = (joints.bending_stiffness - joints.torsional_stiffness) / spacing  # (N·m/rad)
    spec.add_actuator(
      name=torsion_actuator_name(body.name),
      trntype=mujoco.mjtTrn.mjTRN_JOINTINPARENT,
      target=f"{body.name}_ball",
      gear=(1, 0, 0, 0, 0, 0),  # The parent segment's x-axis: the rod's axis before the joint.
      gaintype=mujoco.mjtGain.mjGAIN_FIXED,
      gainprm=[0.0] * 10,  # No control: a passive element.
      biastype=mujoco.mjtBias.mjBIAS_AFFINE,
      biasprm=[0.0, softening] + [0.0] * 8,
      ctrllimited=mujoco.mjtLimited.mjLIMITED_FALSE,
    )


def _add_rod_geom(
  body: mujoco.MjsBody,
  name: str,
  start: float,
  end: float,
  geometry: ChainGeometry,
  rgba: Sequence[float],
) -> None:
  # Cylinders, not capsules: a capsule's caps would overlap its neighbours' and add mass. The
  # cable plugin reads the radius of each body's first geom for E·I and G·J.
  body.add_geom(
    name=name,
    type=mujoco.mjtGeom.mjGEOM_CYLINDER,
    fromto=(start, 0, 0, end, 0, 0),
    size=(geometry.radius, 0, 0),
    density=geometry.density,
    rgba=rgba,
    contype=0,
    conaffinity=0,
  )


def _add_joints(body: mujoco.MjsBody, name: str, joints: SegmentJoints, spacing: float) -> None:
  if joints.slide_stiffness is not None:
    body.add_joint(
      name=f"{name}_slide",
      type=mujoco.mjtJoint.mjJNT_SLIDE,
      axis=(1, 0, 0),
      stiffness=joints.slide_stiffness,
      damping=joints.slide_damping,
      armature=joints.armature,
    )
  body.add_joint(
    name=f"{name}_ball",
    type=mujoco.mjtJoint.mjJNT_BALL,
    stiffness=joints.bending_stiffness / spacing,
    damping=joints.ball_damping,
    armature=joints.armature,
  )


def ring_offsets(radius: float, angles_deg: Sequence[float]) -> list[tuple[float, float]]:
  """(local y, local z) offsets at ``radius`` around the axis at world-frame ``angles_deg``.

  Angles are measured in the world xy-plane of the hanging arm at rest: 0 deg is world +x
  (local +z) and 90 deg is world +y (local +y).
  """
  angles = np.deg2rad(np.asarray(angles_deg, dtype=float))
  return [(float(radius * np.sin(a)), float(radius * np.cos(a))) for a in angles]
