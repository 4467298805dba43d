"""Frames of a replayed episode, drawn in this process with whichever OpenGL backend
dm_control loaded (``MUJOCO_GL``); ``softbench.rendering.video`` runs it in a child process
that chooses the backend."""

from typing import Iterator

from dm_control.mujoco import engine
from dm_control.mujoco import wrapper
import numpy as np

from softbench.rendering import markers
from softbench.rendering import options as video_options
from softbench.rendering import replay as episode_replay
from softbench.rendering import scene


class EpisodeFrames:
  """Renders ``replay`` as ``options`` say; iterate ``frames()`` for (height, width, 3) uint8."""

  def __init__(self, replay: episode_replay.Replay, options: video_options.VideoOptions):
    self.replay = replay
    self.options = options
    model = scene.scene_model(
      replay.robot, scene.episode_points(replay.episode), options.width, options.height
    )
    self.physics = engine.Physics.from_model(wrapper.MjModel(model))
    colours = scene.module_colours(model, replay.robot.num_modules)
    self.markers = markers.EpisodeMarkers(
      replay.episode, colours, replay.robot.length, scene.arm_radius(model), replay.title
    )
    robot_geoms = scene.robot_geom_budget(model)
    self._camera = engine.Camera(
      self.physics,
      options.height,
      options.width,
      options.camera,
      max_geom=robot_geoms + self.markers.geom_count,
      scene_callback=self.markers,
    )
    self._view = wrapper.MjvOption()
    self._view.sitegroup[:] = 0  # Cable holes and bellows anchors would clutter the picture.
    self._scored = np.array(replay.episode.scored_modules) - 1

  @property
  def count(self) -> int:
    return self.options.frame_count(self.replay.steps)

  def frames(self) -> Iterator[np.ndarray]:
    for time, simulated in episode_replay.moments(self.replay, self.options.frames_per_step):
      scene.show_state(self.physics.model.ptr, self.physics.data.ptr, simulated.data.ptr)
      self.markers.at(time, simulated.module_poses()[self._scored, :3])
      caption = self.markers.caption(
        self.options.height, self.options.width, self.physics.contexts.mujoco.ptr.charWidth
      )
      image = self._camera.render(overlays=caption, scene_option=self._view)
      yield image.copy()  # The camera reuses its buffer for the next frame.
