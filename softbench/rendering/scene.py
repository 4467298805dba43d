"""The scene a video is rendered in: the robot's own MJCF plus a floor, lights, a sky and the
named cameras of ``options.CAMERAS``, each placed to frame every point the episode visits.

The robot's bodies, joints and tendons are untouched, so the scene's ``qpos`` is the robot's and
a frame is drawn by copying the simulated state in (``show_state``).
"""

import mujoco
import numpy as np

from softbench import episodes
from softbench.rendering import options
from softbench.robots import base
from softbench.robots import chain

FOVY_DEG = 45.0  # (deg) Vertical field of view of every camera (MuJoCo's default).
FRAME_MARGIN = 1.2  # Framed half-extent over the episode's half-extent.
FLOOR_GAP = 0.35  # Floor distance below the lowest visited point, in arm lengths.
_VIEWS = {  # Camera viewing direction: azimuth and elevation (deg) of where it looks.
  "workspace": (50.0, -25.0),
  "front": (90.0, 0.0),
  "side": (180.0, 0.0),
  "below": (90.0, 90.0),
}
_SKY_RGB = ((0.55, 0.65, 0.75), (0.12, 0.14, 0.18))  # Top and bottom of the gradient sky.
_FLOOR_RGB = ((0.32, 0.34, 0.38), (0.26, 0.28, 0.32))  # Checker squares.
_FLOOR_SQUARES_PER_ARM_LENGTH = 4
_SAMPLES = 0  # Multisamples of the off-screen buffer.
_SLICES = 16  # Slices of round shapes (MuJoCo's default 28).
_ROBOT_GEOM_ALLOWANCE = 4  # Scene geoms per model element (bodies, geoms, tendon pieces...).


def module_colours(model: mujoco.MjModel, num_modules: int) -> np.ndarray:
  """(num_modules, 4) the colour of each module, as its first segment is drawn."""
  return np.array(
    [model.geom(f"{chain.segment_name(k, 1)}_geom").rgba for k in range(1, num_modules + 1)]
  )


def episode_points(episode: episodes.Episode) -> np.ndarray:
  """(n, 3) every point of ``episode`` a frame shows: each module's tip at every step and every
  target position (m)."""
  return np.concatenate(
    [episode.poses[..., :3].reshape(-1, 3), episode.targets[..., :3].reshape(-1, 3)]
  )


def base_plate_points(model: mujoco.MjModel) -> np.ndarray:
  """(4, 3) points on the rim of the top of the robot's base plate (m)."""
  plate = model.geom("base_plate")
  radius, half_height = plate.size[:2]
  top = plate.pos[2] + half_height
  return np.array([[radius, 0, top], [-radius, 0, top], [0, radius, top], [0, -radius, top]])


def _view_axes(camera: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
  """Unit right, up and forward (viewing) directions of ``camera`` in world coordinates."""
  azimuth, elevation = np.radians(_VIEWS[camera])
  forward = np.array(
    [np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)]
  )
  up_hint = np.array([0.0, 0.0, 1.0]) if abs(forward[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
  right = np.cross(forward, up_hint)
  right /= np.linalg.norm(right)
  return right, np.cross(right, forward), forward


def camera_pose(
  camera: str, points: np.ndarray, padding: float, aspect: float
) -> tuple[np.ndarray, np.ndarray]:
  """Position (m) and orientation (quaternion) of ``camera`` such that every point, grown by
  ``padding`` (m) and ``FRAME_MARGIN``, lies in its view for frames of ``aspect`` = width /
  height."""
  right, up, forward = _view_axes(camera)
  across, upward, depth = points @ right, points @ up, points @ forward
  centre_across = (across.min() + across.max()) / 2
  centre_up = (upward.min() + upward.max()) / 2
  tan_vertical = np.tan(np.radians(FOVY_DEG) / 2)
  tan_horizontal = tan_vertical * aspect
  reach_across = (np.abs(across - centre_across) + padding) * FRAME_MARGIN / tan_horizontal
  reach_up = (np.abs(upward - centre_up) + padding) * FRAME_MARGIN / tan_vertical
  camera_depth = np.min(depth - padding - np.maximum(reach_across, reach_up))
  position = centre_across * right + centre_up * up + camera_depth * forward
  rotation = np.stack([right, up, -forward], axis=1)  # Columns: camera x, y, z in world.
  quaternion = np.empty(4)
  mujoco.mju_mat2Quat(quaternion, rotation.ravel())
  return position, quaternion


def scene_model(robot: base.SoftArm, points: np.ndarray, width: int, height: int) -> mujoco.MjModel:
  """The robot in a scene with floor, lights, sky and the cameras of ``options.CAMERAS``, all
  framing ``points`` (m) and the base, with an off-screen buffer of at least ``width`` x
  ``height``."""
  xml = robot.to_xml()
  robot_model = mujoco.MjModel.from_xml_string(xml)
  padding = arm_radius(robot_model)
  points = np.concatenate([points, base_plate_points(robot_model)])
  spec = mujoco.MjSpec.from_string(xml)
  spec.modelname = f"{robot.name} video scene"
  round_segment_ends(spec)
  length = robot.length
  spec.visual.global_.offwidth = max(width, spec.visual.global_.offwidth)
  spec.visual.global_.offheight = max(height, spec.visual.global_.offheight)
  # Software OpenGL (Mesa's llvmpipe) spends most of a frame on multisampling and round
  # shapes: without multisampling and with 16 slices per sphere a 640x480 frame takes about
  # half the time.
  spec.visual.quality.offsamples = _SAMPLES
  spec.visual.quality.numslices = _SLICES
  spec.visual.quality.numstacks = _SLICES // 2
  spec.visual.headlight.ambient = (0.35, 0.35, 0.35)
  spec.visual.headlight.diffuse = (0.55, 0.55, 0.55)
  spec.visual.headlight.specular = (0.1, 0.1, 0.1)
  spec.add_texture(
    name="video_sky",
    type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
    builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
    rgb1=_SKY_RGB[0],
    rgb2=_SKY_RGB[1],
    width=256,
    height=1536,
  )
  spec.add_texture(
    name="video_floor",
    type=mujoco.mjtTexture.mjTEXTURE_2D,
    builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
    rgb1=_FLOOR_RGB[0],
    rgb2=_FLOOR_RGB[1],
    width=64,
    height=64,
  )
  floor_material = spec.add_material(name="video_floor")
  floor_material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "video_floor"
  floor_material.texuniform = True
  floor_material.texrepeat = (_FLOOR_SQUARES_PER_ARM_LENGTH / length,) * 2
  floor_z = points[:, 2].min() - FLOOR_GAP * length
  spec.worldbody.add_geom(
    name="video_floor",
    type=mujoco.mjtGeom.mjGEOM_PLANE,
    size=(0, 0, 0.05),
    pos=(0, 0, floor_z),
    material="video_floor",
    contype=0,
    conaffinity=0,
  )
  spec.worldbody.add_light(
    name="video_key_light",
    pos=(0.5 * length, -0.5 * length, 2 * length),
    dir=(-0.25, 0.25, -1.0),
    type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
    diffuse=(0.5, 0.5, 0.5),
    specular=(0.2, 0.2, 0.2),
    castshadow=False,
  )
  for camera in options.CAMERAS:
    position, quaternion = camera_pose(camera, points, padding, width / height)
    spec.worldbody.add_camera(name=camera, pos=position, quat=quaternion, fovy=FOVY_DEG)
  return spec.compile()


def round_segment_ends(spec: mujoco.MjSpec) -> None:
  """Draws the rod's cylinder segments as capsules of the same radius and axis: where the rod
  bends, cylinders leave wedge-shaped gaps that show their flat ends, so that from above the rod
  looked like an open half-pipe; a capsule's round ends close them. Only the picture changes:
  the scene takes its state from the simulation (``show_state``) and is never stepped."""
  for geom in spec.geoms:
    if geom.type == mujoco.mjtGeom.mjGEOM_CYLINDER and geom.name.startswith("module"):
      geom.type = mujoco.mjtGeom.mjGEOM_CAPSULE


def robot_geom_budget(model: mujoco.MjModel) -> int:
  """Scene geoms to allow for drawing the robot of ``model`` (bodies, geoms, tendon pieces...)."""
  return _ROBOT_GEOM_ALLOWANCE * (
    model.nbody + model.ngeom + model.nsite + model.nwrap + model.ntendon
  )


def arm_radius(model: mujoco.MjModel) -> float:
  """How far the arm's drawing reaches from its axis (m): the thickest segment, or the farthest
  cable or bellows anchor plus its tendon's drawn width."""
  segments = [i for i in range(model.ngeom) if model.geom(i).name.startswith("module")]
  anchors = np.linalg.norm(model.site_pos[:, 1:], axis=1)  # Sites' offsets off the body x-axis.
  widths = model.tendon_width if model.ntendon else np.zeros(1)
  return float(max(model.geom_size[segments, 0].max(), anchors.max() + widths.max()))


def show_state(scene: mujoco.MjModel, scene_data: mujoco.MjData, data: mujoco.MjData) -> None:
  """Puts the simulated state ``data`` (of the robot's own model) into the scene's data."""
  scene_data.qpos[:] = data.qpos
  scene_data.qvel[:] = data.qvel
  scene_data.act[:] = data.act
  scene_data.ctrl[:] = data.ctrl
  scene_data.time = data.time
  mujoco.mj_forward(scene, scene_data)
