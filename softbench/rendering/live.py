"""Frames of a running environment (``gymnasium``'s ``render``), in the videos' scene: the same
floor, lights and named cameras, framing every target of the episode and the arm's start, with
the current target of each scored module drawn in its module's colour.

Drawn in this process with the OpenGL backend dm_control loaded (``MUJOCO_GL``; softbench picks
a headless one when it is unset).
"""

from dm_control.mujoco import engine
from dm_control.mujoco import wrapper
import mujoco
import numpy as np

from softbench.rendering import markers
from softbench.rendering import options as video_options
from softbench.rendering import scene
from softbench.robots import base

_DECORATION_GEOMS = 64  # Scene geoms beyond the robot's: one target marker per scored module.


class LiveView:
  """Renders the physics of an environment of ``robot``; ``start`` at every episode's reset."""

  def __init__(
    self,
    robot: base.SoftArm,
    width: int | None = None,
    height: int | None = None,
    camera: str | None = None,
  ):
    defaults = video_options.VideoOptions()
    self.options = video_options.VideoOptions(
      width=defaults.width if width is None else width,
      height=defaults.height if height is None else height,
      camera=defaults.camera if camera is None else camera,
    )
    self.robot = robot
    self._framed = None  # The points the current scene frames.
    self._physics = self._camera = None
    self._targets = np.zeros((0, 3))
    self._colours = np.zeros((0, 4))
    self._radius = 0.0

  def start(self, physics, task) -> None:
    """Frames the episode that ``task`` just started on ``physics``: all its targets and the
    arm's pose (the scene is rebuilt only when these points change, e.g. a new reach target)."""
    targets = np.stack([task.targets_at(step)[:, :3] for step in range(task.num_steps)])
    points = np.concatenate([targets.reshape(-1, 3), physics.module_poses()[:, :3]])
    if self._framed is not None and np.array_equal(points, self._framed):
      return
    self.close()
    options = self.options
    model = scene.scene_model(self.robot, points, options.width, options.height)
    self._physics = engine.Physics.from_model(wrapper.MjModel(model))
    scored = np.array(task.scored_modules()) - 1
    self._colours = scene.module_colours(model, self.robot.num_modules)[scored]
    self._radius = markers.target_radius(self.robot.length, scene.arm_radius(model))
    geoms = scene.robot_geom_budget(model) + _DECORATION_GEOMS
    self._camera = engine.Camera(
      self._physics,
      options.height,
      options.width,
      options.camera,
      max_geom=geoms,
      scene_callback=self._draw_targets,
    )
    self._view = wrapper.MjvOption()
    self._view.sitegroup[:] = 0  # Cable holes and bellows anchors would clutter the picture.
    self._framed = points

  def _draw_targets(self, physics, frame_scene: mujoco.MjvScene) -> None:
    del physics
    for target, colour in zip(self._targets, self._colours):
      markers.add_geom(
        frame_scene,
        mujoco.mjtGeom.mjGEOM_SPHERE,
        (self._radius,) * 3,
        target,
        markers.target_rgba(colour),
      )

  def render(self, physics, task) -> np.ndarray:
    """(height, width, 3) uint8: the arm as ``physics`` holds it, and ``task``'s current
    targets."""
    if self._camera is None:
      raise RuntimeError("render() needs an episode: call reset() first")
    scene.show_state(self._physics.model.ptr, self._physics.data.ptr, physics.data.ptr)
    self._targets = task.targets_at(task.steps_done)[:, :3]
    return self._camera.render(scene_option=self._view).copy()

  def close(self) -> None:
    if self._camera is not None:
      self._camera.scene.free()
      self._camera = None
    if self._physics is not None:
      self._physics.free()
      self._physics = None
    self._framed = None
