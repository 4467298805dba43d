"""The plugin-free rod (``backbone="rod"``, physics v1): equal to MuJoCo 3's cable plugin, and
right by beam theory.

The cable plugin's equilibria are stored (``tests/data/cable_equilibria.json``, made on MuJoCo
3.17 by ``tests/data/cable_equilibria.py``), so the comparison runs on any MuJoCo. Measured
2026-12-06 on both stacks: the rod's tips lie within 7e-5 mm of the stored ones on every tendon
arm N = 1 .. 5 of both families (8 settled random two-axis actions each); the generalised forces
agree to 4e-7 relative (the XML's 6 significant digits).
"""

import json
import math
import pathlib

import mujoco
import numpy as np
import pytest
from scipy import integrate

from softbench import robots
from softbench.robots import chain
from softbench.robots import measure
from softbench.robots import versions

CABLE_EQUILIBRIA = json.loads(
  (pathlib.Path(__file__).parent / "data" / "cable_equilibria.json").read_text()
)
EQUIVALENCE_TOLERANCE = 0.05e-3  # (m) The bound; measured worst 7e-8 m.
BEAM_TOLERANCE = 0.01  # Fraction of the rod's length; measured worst 0.9 % at 7 segments.
BEAM_SETTLE_S = 6.0  # (s) Gravity off; the tip moves < 1e-9 m in the last second.


def _tendon_arms() -> list[str]:
  families, sizes = robots.TENDON_FAMILY_NAMES, robots.BENCHMARK_MODULES
  return [f"{family}-{n}" for family in families for n in sizes]


def test_the_reference_covers_every_benchmark_tendon_arm():
  assert sorted(CABLE_EQUILIBRIA["robots"]) == sorted(_tendon_arms())


@pytest.mark.parametrize("name", _tendon_arms())
def test_rod_equilibria_equal_the_cable_plugins(name):
  stored = CABLE_EQUILIBRIA["robots"][name]
  arm = robots.make(name, backbone="rod")
  model = arm.compile()
  worst = 0.0
  for action, cable_tips in zip(stored["actions"], stored["tips_m"]):
    tips = measure.equilibrium(arm, np.array(action), CABLE_EQUILIBRIA["hold_s"], model)
    worst = max(worst, float(np.linalg.norm(tips - np.array(cable_tips), axis=1).max()))
  print(f"{name}: {worst * 1e3:.2e} mm")
  assert worst < EQUIVALENCE_TOLERANCE, f"{name}: {worst * 1e3:.4f} mm from the cable plugin"


def _torsion_free_state(arm) -> tuple[mujoco.MjModel, mujoco.MjData]:
  model = arm.compile()
  model.opt.gravity[:] = 0.0
  return model, mujoco.MjData(model)


def _settle(model, data, load) -> np.ndarray:
  """Steps ``BEAM_SETTLE_S`` with ``load(model, data)`` setting ``qfrc_applied`` before each
  step; returns the end effector's position (m)."""
  tip = model.site(chain.tip_site_name(_last_module(model))).id
  for _ in range(int(round(BEAM_SETTLE_S / model.opt.timestep))):
    data.qfrc_applied[:] = 0.0
    load(model, data, tip)
    mujoco.mj_step(model, data)
  mujoco.mj_kinematics(model, data)
  return data.site_xpos[tip].copy()


def _last_module(model) -> int:
  module = 1
  while mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, chain.tip_site_name(module + 1)) >= 0:
    module += 1
  return module


@pytest.mark.parametrize("name", ["tendon-1", "tendon-3"])
@pytest.mark.parametrize("backbone", robots.tendon.BACKBONES)
def test_a_tip_moment_bends_the_rod_into_a_circle(name, backbone):
  # Constant curvature kappa = M / (E I): the tip lies on a circle of radius 1 / kappa.
  if backbone == "cable" and not versions.cable_plugin_available():
    pytest.skip(versions.cable_plugin_missing())
  arm = robots.make(name, backbone=backbone)
  length = arm.length
  moment = 1.0 * arm.bending_stiffness / length  # Bends the rod through 1 rad.
  model, data = _torsion_free_state(arm)

  def load(model, data, tip):
    body = model.site_bodyid[tip]
    mujoco.mj_applyFT(
      model,
      data,
      np.zeros(3),
      np.array([0.0, moment, 0.0]),
      data.site_xpos[tip],
      body,
      data.qfrc_applied,
    )

  tip = _settle(model, data, load)
  curvature = moment / arm.bending_stiffness
  angle = curvature * length
  # Hanging along -z from the base at the origin; a moment about +y turns the rod towards -x.
  expected = np.array([-(1 - math.cos(angle)) / curvature, 0.0, -math.sin(angle) / curvature])
  error = np.linalg.norm(tip - expected) / length
  print(f"{name} {backbone} circle: {error:.3%}")
  assert error < BEAM_TOLERANCE, f"{error:.2%} of the length from the circle"


def _elastica_tip(length: float, force: float, bending_stiffness: float) -> np.ndarray:
  """(x, z) of the free end of a cantilever hanging along -z with a dead load ``force`` along +x
  at its end: E I theta'' = -F cos(theta), theta(0) = 0, theta'(L) = 0."""
  load = force / bending_stiffness

  def rhs(s, y):
    return np.vstack([y[1], -load * np.cos(y[0])])

  s = np.linspace(0.0, length, 201)
  guess = np.vstack([load * length * s / 2, load * (length - s)])
  solution = integrate.solve_bvp(rhs, lambda ya, yb: np.array([ya[0], yb[1]]), s, guess, tol=1e-10)
  assert solution.success, solution.message
  theta = solution.sol(s)[0]
  return np.array([integrate.trapezoid(np.sin(theta), s), -integrate.trapezoid(np.cos(theta), s)])


@pytest.mark.parametrize("name", ["tendon-1", "tendon-3"])
@pytest.mark.parametrize("backbone", robots.tendon.BACKBONES)
def test_a_tip_force_bends_the_rod_into_the_elastica(name, backbone):
  if backbone == "cable" and not versions.cable_plugin_available():
    pytest.skip(versions.cable_plugin_missing())
  arm = robots.make(name, backbone=backbone)
  length = arm.length
  force = 2.0 * arm.bending_stiffness / length**2  # A large deflection: the tip turns ~ 60 deg.
  model, data = _torsion_free_state(arm)

  def load(model, data, tip):
    mujoco.mj_applyFT(
      model,
      data,
      np.array([force, 0.0, 0.0]),
      np.zeros(3),
      data.site_xpos[tip],
      model.site_bodyid[tip],
      data.qfrc_applied,
    )

  tip = _settle(model, data, load)
  x, z = _elastica_tip(length, force, arm.bending_stiffness)
  error = np.linalg.norm(tip - np.array([x, 0.0, z])) / length
  print(f"{name} {backbone} elastica: {error:.3%}, x {x / length:.3f} L")
  assert x > 0.3 * length  # A large deflection, not the linear regime.
  assert error < BEAM_TOLERANCE, f"{error:.2%} of the length from the elastica"


@pytest.mark.parametrize("name", ["tendon-3", "tendon-local-3"])
def test_the_rod_twists_with_g_j_and_bends_with_e_i(name):
  # Small rotations of one joint: the generalised force is -diag(G J, E I, E I) omega / l.
  arm = robots.make(name, backbone="rod")
  model = arm.compile()
  data = mujoco.MjData(model)
  joint = model.joint("module1_segment3_ball")
  adr, dof = joint.qposadr[0], joint.dofadr[0]
  stiffness = np.array([arm.torsional_stiffness, *[arm.bending_stiffness] * 2])
  for axis in range(3):
    omega = np.zeros(3)
    omega[axis] = 1e-4
    mujoco.mju_axisAngle2Quat(data.qpos[adr : adr + 4], omega / 1e-4, 1e-4)
    mujoco.mj_forward(model, data)
    force = (data.qfrc_passive + data.qfrc_actuator)[dof : dof + 3]
    expected = -stiffness[axis] * omega[axis] / arm.segment_length
    assert force[axis] == pytest.approx(expected, rel=1e-5)
    data.qpos[:] = model.qpos0


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_no_benchmark_robot_needs_a_plugin_with_the_rod(name):
  spec = robots.make(name, **({"backbone": "rod"} if robots.is_tendon(name) else {}))
  xml = spec.to_xml()
  assert "<plugin" not in xml and "<extension" not in xml
