"""Property tests over every robot of the registry (dm_control ``suite_test`` style).

Every test that takes ``robot_name`` runs once per entry of ``REGISTERED_ROBOTS``, so a new robot
is covered without new code. Physics runs through ``SoftArmPhysics`` (the class controllers use,
built from the exported XML), but is stepped with ``mujoco.mj_step(model, data, nstep=...)`` on
its raw structs rather than dm_control's Python step loop, for speed.

Figures measured with mujoco 3.17.0 on CPU, quoted where each tolerance is chosen.
"""

import math
import re

import mujoco
import numpy as np
import pytest

from softbench.robots import MAX_MODULES
from softbench.robots import REGISTERED_ROBOTS
from softbench.robots import TENDON_FAMILY_NAMES
from softbench.robots import catalogue
from softbench.robots import family_of
from softbench.robots import is_tendon
from softbench.robots import make
from softbench.robots import measure
from softbench.robots import payload as payload_model
from softbench.robots import pneumatic
from softbench.robots import versions
from softbench.robots.physics import SoftArmPhysics
from softbench.robots.tendon import BACKBONES as TENDON_BACKBONES

# Object kind (the MjModel accessor) and the MjModel attribute that counts them.
NAMED_OBJECTS = {
  "body": "nbody",
  "joint": "njnt",
  "geom": "ngeom",
  "site": "nsite",
  "tendon": "ntendon",
  "actuator": "nu",
}
WARNINGS = [kind for name, kind in mujoco.mjtWarning.__members__.items() if name != "mjNWARNING"]

RANDOM_ACTUATION_S = 10.0
REST_S = 2.0
REST_MAX_QVEL = 1e-3  # (rad/s or m/s) Tendon arms: exactly 0 at rest.
REST_MAX_TIP_DRIFT = 0.05e-3  # (m) Once settled, the tips stay put.
REST_MAX_SAG_FRACTION = 0.01  # Sag under gravity from the built, straight pose, of the length.
# A step to a non-zero action held HOLD_S, then back to zero action. Last time (s) any tip was
# farther than 1 mm from rest, worst of 10 actions (all +1, all -1, 8 random), measured on the
# models of 2026-12-03 in 0.25 s steps: tendon-3 0.5, tendon-5 1.0, tendon-local-5 1.0,
# pneumatic-433 1.0 (an older model's tendon-5 took 15.85 s, hence the former 25 s).
HOLD_S = 2.0
RETURN_S = 5.0
RETURN_TOLERANCE = 1e-3  # (m)
# Mirror images agree to 2e-15 m (tips) and 3e-14 (orientation vectors) after 3 s, for full-range
# random actions: the models are symmetric to rounding and no chaos shows up. The whole trajectory
# is symmetric, so the arms, still moving at 1 s, need not have reached equilibrium.
MIRROR_SETTLE_S = 1.0
MIRROR_TOLERANCE = 1e-6
# Bend angles after 2 s and after 5 s of settling agree to 0.01 degree on every registered robot
# (measured 2026-12-03), while consecutive actuation levels are 7 degrees or more apart.
BEND_SETTLE_S = 2.0
BEND_LEVELS = (0.2, 0.4, 0.6, 0.8, 1.0)
# Gravity off, module k fully actuated alone for 3 s (measure.gravity_free_tilts): the proximal
# modules' tips turn by 0.0 deg on every tendon-local arm (exactly: no load reaches them), and by
# 30.6 deg or more on every tendon-N arm (tendon-3, module 3: 30.6 and 61.2 deg).
PROXIMAL_TILT_DEG = {"tendon": (10.0, math.inf), "tendon-local": (0.0, 1.0)}


def _expected_size(name: str) -> tuple[int, int]:
  """(num_modules, action_dim) that a registry name promises."""
  if match := re.fullmatch(r"tendon(?:-local)?-(\d+)", name):
    return int(match.group(1)), 2 * int(match.group(1))
  if match := re.fullmatch(r"pneumatic-(\d+)", name):
    bellows = [int(digit) for digit in match.group(1)]
    return len(bellows), sum(bellows)
  raise AssertionError(f"no size rule for robot family of {name!r}; add one to this test")


def _robots(xfail: dict[str, str] | None = None) -> list:
  """``REGISTERED_ROBOTS`` as pytest params; ``xfail`` maps a name to a known, measured failure."""
  xfail = xfail or {}
  return [
    pytest.param(
      name,
      id=name,
      marks=[pytest.mark.xfail(strict=True, reason=xfail[name])] if name in xfail else [],
    )
    for name in REGISTERED_ROBOTS
  ]


def new_physics(robot) -> SoftArmPhysics:
  """The robot's physics at its initial state, with zero action applied."""
  physics = SoftArmPhysics.from_robot(robot)
  physics.set_action(np.zeros(robot.action_dim))
  physics.forward()
  return physics


def steps(physics: SoftArmPhysics, seconds: float) -> int:
  return int(round(seconds / physics.model.opt.timestep))


def advance(physics: SoftArmPhysics, seconds: float = 0.0, nstep: int | None = None) -> None:
  """Steps the physics ``seconds`` (or ``nstep`` steps) under its current controls."""
  model, data = physics.model.ptr, physics.data.ptr
  mujoco.mj_step(model, data, nstep=steps(physics, seconds) if nstep is None else nstep)
  mujoco.mj_forward(model, data)  # Poses of the final state, not of the one before it.


def settle(robot, action, seconds: float) -> SoftArmPhysics:
  """Physics after ``seconds`` of constant ``action`` from the initial state."""
  physics = new_physics(robot)
  physics.set_action(action)
  advance(physics, seconds)
  return physics


def tips(physics: SoftArmPhysics) -> np.ndarray:
  """(num_modules, 3) tip positions (m)."""
  return physics.module_poses()[:, :3]


def axes(physics: SoftArmPhysics) -> np.ndarray:
  """(num_modules, 3) unit orientation vectors at the module tips."""
  return physics.module_poses()[:, 3:]


def bending_action(robot, module: int, level: float) -> np.ndarray:
  """Action that bends ``module`` (1-based) one way, with magnitude ``level``."""
  action = np.zeros(robot.action_dim)
  entries = robot.module_action_slices()[module - 1]
  if robot.name.startswith("tendon-"):
    action[entries.start] = level  # The module's x axis.
  else:  # Bellows 1 deflates, the others inflate.
    action[entries] = level
    action[entries.start] = -level
  return action


def _random_actions(robot, count: int, seed: int, scale: float = 1.0) -> list[np.ndarray]:
  rng = np.random.default_rng(seed)
  return [scale * rng.uniform(-1.0, 1.0, robot.action_dim) for _ in range(count)]


# 1. Structure.


@pytest.mark.parametrize("robot_name", _robots())
def test_compiles_with_promised_sizes(robot_name):
  robot = make(robot_name)
  model = robot.compile()
  num_modules, action_dim = _expected_size(robot_name)
  assert robot.name == robot_name
  assert robot.num_modules == num_modules
  assert robot.action_dim == action_dim
  slices = robot.module_action_slices()
  assert len(slices) == num_modules
  assert [i for s in slices for i in range(s.start, s.stop)] == list(range(action_dim))
  physics = SoftArmPhysics.from_robot(robot)
  assert physics.num_modules == num_modules
  assert physics.action_dim == action_dim
  assert model.nu == len(robot.actuator_maps())
  assert robot.mass(model) > 0


@pytest.mark.parametrize("robot_name", _robots())
@pytest.mark.parametrize("kind", NAMED_OBJECTS)
def test_every_element_has_a_unique_name(robot_name, kind):
  model = make(robot_name).compile()
  count = getattr(model, NAMED_OBJECTS[kind])
  assert count > 0
  names = [getattr(model, kind)(i).name for i in range(count)]
  assert all(names), f"unnamed {kind} ids: {[i for i, n in enumerate(names) if not n]}"
  duplicates = sorted({n for n in names if names.count(n) > 1})
  assert not duplicates, f"duplicate {kind} names: {duplicates}"


# 2. Stability under random actuation.


@pytest.mark.parametrize("robot_name", _robots())
def test_random_actuation_is_stable(robot_name):
  robot = make(robot_name)
  physics = new_physics(robot)
  rng = np.random.default_rng(0)
  data = physics.data.ptr
  farthest = 0.0
  per_action = steps(physics, robot.control_timestep)
  for _ in range(int(round(RANDOM_ACTUATION_S / robot.control_timestep))):
    physics.set_action(rng.uniform(-1.0, 1.0, robot.action_dim))
    for chunk in np.array_split(np.arange(per_action), 10):  # Checks 10 times per action.
      advance(physics, nstep=len(chunk))
      assert np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel)), (
        f"non-finite state at t = {data.time:.3f} s"
      )
      farthest = max(farthest, float(np.linalg.norm(tips(physics)[-1])))
  raised = {kind.name: data.warning[kind].number for kind in WARNINGS if data.warning[kind].number}
  assert not raised, f"MuJoCo warnings: {raised}"
  # MuJoCo resets diverged data to time 0 (with a warning); the clock must have run through.
  assert data.time == pytest.approx(RANDOM_ACTUATION_S, abs=robot.control_timestep / 2)
  # The base is at the world origin: a tendon arm cannot stretch, a bellows module at most to
  # MAX_LENGTH_RATIO. Measured farthest / length over 3 seeds: tendon-N 0.989 to 0.9995,
  # pneumatic-433 1.096.
  stretch = 1.0 + 1e-9 if robot_name.startswith("tendon-") else pneumatic.MAX_LENGTH_RATIO
  assert farthest <= stretch * robot.length, f"tip {farthest / robot.length:.3f} lengths away"


# 3. Rest.


@pytest.mark.parametrize("robot_name", _robots())
def test_rests_at_zero_action(robot_name):
  """At zero action the arm settles: it sags under gravity by at most a fraction of its length
  within REST_S, then stays still."""
  robot = make(robot_name)
  physics = new_physics(robot)
  start = tips(physics)
  advance(physics, REST_S)
  settled = tips(physics)
  max_qvel = np.abs(physics.data.qvel).max()
  advance(physics, REST_S)
  sag = np.linalg.norm(settled - start, axis=1).max()
  drift = np.linalg.norm(tips(physics) - settled, axis=1).max()
  figures = (
    f"after {REST_S} s: max |qvel| = {max_qvel:.3g}, sag {sag * 1e3:.3f} mm; "
    f"then drift {drift * 1e3:.4f} mm"
  )
  assert max_qvel < REST_MAX_QVEL, figures
  assert sag < REST_MAX_SAG_FRACTION * robot.length, figures
  assert drift < REST_MAX_TIP_DRIFT, figures


@pytest.mark.parametrize("robot_name", _robots())
def test_returns_to_rest_after_a_step(robot_name):
  robot = make(robot_name)
  # Rest is where zero action leaves the arm after the same total time.
  rest = tips(settle(robot, np.zeros(robot.action_dim), HOLD_S + RETURN_S))
  steps = [np.ones(robot.action_dim)] + _random_actions(robot, 1, seed=1)
  for action in steps:
    physics = settle(robot, action, HOLD_S)
    moved = np.linalg.norm(tips(physics) - rest, axis=1).max()
    assert moved > 10 * RETURN_TOLERANCE, "the step did not move the arm"
    physics.set_action(np.zeros(robot.action_dim))
    advance(physics, RETURN_S)
    error = np.linalg.norm(tips(physics) - rest, axis=1).max()
    assert error < RETURN_TOLERANCE, (
      f"{error * 1e3:.3f} mm from rest {RETURN_S} s after releasing {np.round(action, 3)}"
    )


# 4. Mirror symmetry.


@pytest.mark.parametrize("robot_name", _robots())
def test_mirrored_action_gives_mirrored_pose(robot_name):
  robot = make(robot_name)
  mirror = robot.mirror_matrix
  np.testing.assert_allclose(mirror @ mirror.T, np.eye(3), atol=1e-12)
  assert abs(np.linalg.det(mirror)) == pytest.approx(1.0)
  for action in _random_actions(robot, 3, seed=2):
    np.testing.assert_array_equal(robot.mirror_action(robot.mirror_action(action)), action)
    poses = settle(robot, action, MIRROR_SETTLE_S).module_poses()
    mirrored = settle(robot, robot.mirror_action(action), MIRROR_SETTLE_S).module_poses()
    expected = np.concatenate([poses[:, :3] @ mirror.T, poses[:, 3:] @ mirror.T], axis=1)
    # Not trivially symmetric: the pose differs from its own mirror image.
    assert np.abs(poses - expected).max() > 1e-3
    np.testing.assert_allclose(mirrored, expected, rtol=0, atol=MIRROR_TOLERANCE)


# 5. Bending grows with actuation.


@pytest.mark.parametrize("robot_name", _robots())
def test_bending_grows_with_actuation(robot_name):
  robot = make(robot_name)
  rest = axes(settle(robot, np.zeros(robot.action_dim), BEND_SETTLE_S))
  for module in sorted({1, robot.num_modules}):
    angles = []
    for level in BEND_LEVELS:
      axis = axes(settle(robot, bending_action(robot, module, level), BEND_SETTLE_S))[module - 1]
      angles.append(np.degrees(np.arccos(np.clip(axis @ rest[module - 1], -1.0, 1.0))))
    assert angles[0] > 1.0, f"module {module}: {angles[0]:.2f} deg at level {BEND_LEVELS[0]}"
    assert np.all(np.diff(angles) > 0), (
      f"module {module} bend angles (deg) not increasing: {np.round(angles, 2).tolist()}"
    )


# 5b. Where a module's actuators act: within the module, or through the proximal ones too.


def _multi_module_tendon_arms() -> list:
  return [
    pytest.param(name, id=name)
    for name in REGISTERED_ROBOTS
    if is_tendon(name) and make(name).num_modules > 1
  ]


@pytest.mark.parametrize("robot_name", _multi_module_tendon_arms())
def test_a_module_turns_the_proximal_ones_as_its_family_routes_cables(robot_name):
  robot = make(robot_name)
  low, high = PROXIMAL_TILT_DEG[family_of(robot_name).name]
  for module in range(2, robot.num_modules + 1):
    tilts = measure.gravity_free_tilts(robot, module)
    proximal = tilts[: module - 1]
    assert low <= proximal.min() and proximal.max() <= high, (
      f"module {module} turns the tips by {np.round(tilts, 2).tolist()} deg"
    )
    assert tilts[module - 1] > 45.0, f"module {module}'s own tip turns {tilts[module - 1]:.1f} deg"


def test_a_one_module_local_arm_is_the_one_module_arm():
  # Module 1's cables start at the clamp in both families; only their hole names differ.
  local, crossing = make("tendon-local-1"), make("tendon-1")
  for action in _random_actions(local, 3, seed=4) + [np.ones(2)]:
    np.testing.assert_array_equal(
      settle(local, action, 1.0).module_poses(), settle(crossing, action, 1.0).module_poses()
    )


@pytest.mark.parametrize("robot_name", REGISTERED_ROBOTS)
def test_a_payload_adds_its_mass_at_the_tip_and_none_changes_nothing(robot_name):
  robot, grams = make(robot_name), 7.0
  assert make(robot_name, payload=0.0).to_xml() == robot.to_xml()
  loaded = make(robot_name, payload=grams / 1000)
  assert loaded.mass() - robot.mass() == pytest.approx(grams / 1000)
  model = loaded.compile()
  tip = model.site(f"module{robot.num_modules}_tip")
  assert model.body(payload_model.BODY).parentid[0] == tip.bodyid[0]


# 6. Bad input.


@pytest.mark.parametrize(
  "name, overrides",
  [
    ("tendon-0", {}),
    ("tendon-x", {}),
    ("tendon-1000", {}),
    ("tendon-local-0", {}),
    ("tendon-local-x", {}),
    (f"tendon-local-{MAX_MODULES + 1}", {}),
    ("tendon-local-3", {"pass_through_offset": 0.002}),  # No cable crosses a proximal module.
    ("tendon-3", {"FAMILY": "tendon-local"}),
    (f"tendon-{MAX_MODULES + 1}", {}),
    ("foo", {}),
    ("tendon-3", {"module_length": -0.05}),
    ("tendon-3", {"no_such_field": 1}),
    ("tendon-3", {"backbone": "spring"}),
    ("pneumatic-433", {"no_such_field": 1}),
    # Canonical ASCII names only: each of these once built another robot, or Python's message.
    ("tendon-\uff13", {}),  # Full-width 3.
    ("tendon-\u0662", {}),  # Arabic-Indic 2.
    ("tendon-3\n", {}),
    (" tendon-3", {}),
    ("tendon-0003", {}),
    ("tendon-" + "9" * 5000, {}),
    ("tendon-1", {"num_modules": 0}),  # The name gives the count.
    ("tendon-1", {"num_modules": 2}),
    ("tendon-3", {"payload": -0.005}),
    ("tendon-3", {"payload": float("nan")}),
    ("pneumatic-433", {"payload": 2.0}),  # Over robots.payload.MAX_PAYLOAD.
    ("tendon-local-2", {"payload": True}),
  ],
  ids=lambda value: repr(value)[:40],
)
def test_bad_robot_raises_one_line_value_error(name, overrides):
  with pytest.raises(ValueError) as caught:
    make(name, **overrides)
  message = str(caught.value)
  assert message.strip() and "\n" not in message and len(message) < 200


@pytest.mark.parametrize("robot_name", _robots())
def test_set_action_rejects_bad_actions(robot_name):
  robot = make(robot_name)
  physics = new_physics(robot)
  dim = robot.action_dim
  valid = np.full(dim, 0.5)
  physics.set_action(valid)
  ctrl = physics.data.ctrl.copy()
  nan = valid.copy()
  nan[-1] = np.nan
  inf = valid.copy()
  inf[0] = np.inf
  high = valid.copy()
  high[0] = 1.01
  low = valid.copy()
  low[-1] = -1.5
  for bad in (
    nan,
    inf,
    high,
    low,
    np.zeros(dim + 1),
    np.zeros(dim - 1),
    np.zeros((1, dim)),
    np.float64(0.0),
    valid + 0.1j,
    np.ones(dim, dtype=bool),
    np.array(["0.5"] * dim),
  ):
    with pytest.raises(ValueError) as caught:
      physics.set_action(bad)
    assert "\n" not in str(caught.value)
    np.testing.assert_array_equal(physics.data.ctrl, ctrl)  # A rejected action changes nothing.
  physics.set_action(np.ones(dim))  # The range's ends are valid.
  physics.set_action(-np.ones(dim))


@pytest.mark.parametrize("name", [*REGISTERED_ROBOTS, "tendon-7", f"tendon-local-{MAX_MODULES}"])
def test_the_catalogue_knows_a_robot_as_built(name):
  # What the records and the leaderboard read without MuJoCo is what the built arm says.
  robot = make(name)
  assert (catalogue.num_modules(name), catalogue.length(name)) == (robot.num_modules, robot.length)
  assert catalogue.is_tendon(name) == (family_of(name).name in TENDON_FAMILY_NAMES)


@pytest.mark.parametrize("bad", ["tendon-0", "tendon-11", "tendon-03", "x", "tendon-local-x", 3])
def test_the_catalogue_refuses_a_name_as_make_does(bad):
  with pytest.raises(ValueError) as built:
    make(bad)
  with pytest.raises(ValueError) as counted:
    catalogue.num_modules(bad)
  assert str(counted.value) == str(built.value) and "\n" not in str(built.value)


@pytest.mark.parametrize("family", TENDON_FAMILY_NAMES)
@pytest.mark.parametrize("num_modules", range(1, MAX_MODULES + 1))
def test_every_tendon_arm_builds(family, num_modules):
  robot = make(f"{family}-{num_modules}")
  model = robot.compile()
  assert robot.num_modules == num_modules
  assert model.ntendon == 4 * num_modules
  assert len(robot.actuator_maps()) == model.nu
  cables = [a for a in range(model.nu) if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_TENDON]
  assert cables == list(range(4 * num_modules))  # The cables first; the rod's torsion after.
  tip_sites = [f"module{k}_tip" for k in range(1, num_modules + 1)]
  assert [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, s) >= 0 for s in tip_sites] == (
    [True] * num_modules
  )
  assert robot.length == pytest.approx(0.05 * num_modules)


# 7. The rod against the cable plugin and beam theory: tests/test_rod.py.


# 7b. Discretisation: refining the chain must not change the module's material.


def _module_series_compliance(model: mujoco.MjModel, module: int, kind: str) -> float:
  """Sum of 1 / stiffness over a module's joints of ``kind`` ("slide" or "ball"): the compliance
  of those springs in series; 0 when the module has none or they carry no stiffness."""
  names = [model.joint(j).name for j in range(model.njnt)]
  stiffness = [
    model.jnt_stiffness[j]
    for j, name in enumerate(names)
    if name.startswith(f"module{module}_segment") and name.endswith(f"_{kind}")
  ]
  return float(sum(1.0 / k for k in stiffness if k > 0))


def _rod_segments(model: mujoco.MjModel, module: int) -> list[int]:
  """Body ids of a module's rod segments."""
  return [b for b in range(model.nbody) if model.body(b).name.startswith(f"module{module}_segment")]


def _torsion_softening(model: mujoco.MjModel, module: int) -> dict[str, float]:
  """Each of a module's joints' torsion actuator's bias (N·m/rad), by joint name."""
  return {
    model.joint(model.actuator_trnid[a][0]).name: float(model.actuator_biasprm[a][1])
    for a in range(model.nu)
    if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINTINPARENT
    and model.joint(model.actuator_trnid[a][0]).name.startswith(f"module{module}_segment")
  }


def _module_twist_compliance(model: mujoco.MjModel, module: int) -> float:
  """Sum of 1 / (twisting stiffness) over a module's ball joints: the ball spring less its torsion
  actuator's softening; 0 where the cable plugin carries the elasticity."""
  softening = _torsion_softening(model, module)
  return float(
    sum(
      1.0 / (model.jnt_stiffness[j] - softening.get(model.joint(j).name, 0.0))
      for j in range(model.njnt)
      if model.joint(j).name.startswith(f"module{module}_segment")
      and model.joint(j).name.endswith("_ball")
      and model.jnt_stiffness[j] > 0
    )
  )


# Every backbone the robots build: the tendon arms' rod (ball springs and torsion actuators) and,
# where MuJoCo 3 is installed, their cable plugin; the pneumatic arm's ball and slide springs.
_BACKBONES = [pytest.param(name, {}, id=name) for name in REGISTERED_ROBOTS] + [
  pytest.param(name, {"backbone": backbone}, id=f"{name}-{backbone}")
  for name in REGISTERED_ROBOTS
  if name.startswith("tendon-")
  for backbone in TENDON_BACKBONES
  if backbone != versions.current().backbone
  and (backbone != "cable" or versions.cable_plugin_available())
]


@pytest.mark.parametrize("robot_name, overrides", _BACKBONES)
@pytest.mark.parametrize("factor", [2, 3])
def test_refining_keeps_every_module_material(robot_name, overrides, factor):
  # Springs per joint that do not scale with the segment count soften a module as it is refined;
  # the pneumatic arm's slide joints did, and its discretisation error was 7.1 % of the length
  # instead of 0.43 %. The cable plugin derives each element's stiffness from E, G, the rod's
  # radius and the element's length, so there every segment must keep the plugin and the radius.
  robot = make(robot_name, **overrides)
  coarse, fine = robot.compile(), robot.refined(factor).compile()
  # Segments straddle module boundaries (the rod is staggered), so mass is compared as a whole;
  # the exported XML keeps 6 significant digits.
  assert robot.mass(fine) == pytest.approx(robot.mass(coarse), rel=1e-5)
  assert fine.nplugin == coarse.nplugin
  assert bytes(fine.plugin_attr) == bytes(coarse.plugin_attr)  # The plugin's E and G.
  for module in range(1, robot.num_modules + 1):
    radii = []
    for model in (coarse, fine):
      segments = _rod_segments(model, module)
      assert len(segments) == robot.segments_per_module * (1 if model is coarse else factor)
      assert {int(model.body_plugin[b]) >= 0 for b in segments} == {coarse.nplugin > 0}, module
      radii.append(
        {
          float(model.geom_size[g][0])
          for g in range(model.ngeom)
          if model.geom_bodyid[g] in segments
        }
      )
    assert len(radii[0]) == 1 and radii[1] == radii[0], (module, radii)
    if coarse.nplugin == 0:  # Springs carry the elasticity: every module has bending springs.
      assert _module_series_compliance(coarse, module, "ball") > 0, module
    for kind in ("slide", "ball"):
      assert _module_series_compliance(fine, module, kind) == pytest.approx(
        _module_series_compliance(coarse, module, kind), rel=1e-5
      ), (module, kind)
    assert _module_twist_compliance(fine, module) == pytest.approx(
      _module_twist_compliance(coarse, module), rel=1e-5
    ), module


# 8. Exported XML.


@pytest.mark.parametrize("robot_name", _robots())
def test_exported_xml_round_trips(robot_name):
  robot = make(robot_name)
  model = robot.compile()
  reloaded = mujoco.MjModel.from_xml_string(robot.to_xml())
  for size in ("nbody", "nq", "nv", "nu", "ntendon", "nsite", "njnt"):
    assert getattr(reloaded, size) == getattr(model, size), size
  np.testing.assert_allclose(reloaded.body_mass, model.body_mass, rtol=1e-6)
  # The XML writer rounds the last bit of some numbers (0.055999999999999994 -> 0.056).
  np.testing.assert_allclose(
    reloaded.numeric("action_map").data, model.numeric("action_map").data, rtol=1e-12, atol=0
  )
