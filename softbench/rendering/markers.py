"""What a frame draws beside the robot: the target trail, the achieved tip path and a caption.

Every scored module gets, in a tint of its own colour, small markers along its whole target
trajectory, a larger marker on the target of the current step and, up to the current moment,
the path its tip has taken. Long trajectories are subsampled to at most ``MAX_TRAIL_MARKERS``
markers and about ``MAX_PATH_SEGMENTS`` path segments per module (the path through every k-th
step, the same steps in every frame, so that it does not shimmer as it grows).
"""

from collections.abc import Sequence
import functools

from dm_control.mujoco import engine
import mujoco
import numpy as np

from softbench import episodes
from softbench import metrics

MAX_TRAIL_MARKERS = 400  # Per module.
MAX_PATH_SEGMENTS = 400  # Per module.
TRAIL_RADIUS = 0.006  # Trail marker radius, in arm lengths.
TARGET_RADIUS = 0.022  # Current-target marker radius, in arm lengths, or
TARGET_ARM_SHARE = 1.3  # this share of the arm's drawn radius if larger: a target on the tip
# shows as a translucent halo around it rather than hiding inside the arm.
TARGET_ALPHA = 0.45
PATH_RADIUS = 0.005  # Achieved-path capsule radius, in arm lengths.
TRAIL_ALPHA = 0.55
MIN_CAPTION_HEIGHT = 240  # (pixels) Smaller frames get no caption, which would cover them.
# Layout of mjr_overlay's text boxes, measured at dm_control's font scale (150): a box reaches
# OVERLAY_EDGE_PX plus its text's width in from the frame's edge, and its two columns are
# OVERLAY_GAP_PX apart.
OVERLAY_EDGE_PX = 17
OVERLAY_GAP_PX = 11
_WHITE = np.ones(4)


def _tint(colour: np.ndarray, towards: np.ndarray, amount: float, alpha: float) -> np.ndarray:
  mixed = (1 - amount) * np.asarray(colour, float) + amount * towards
  return np.append(mixed[:3], alpha).astype(np.float32)


def _text_width(text: str, char_widths: Sequence[int]) -> int:
  """Pixel width of the widest line of ``text`` (ASCII) in a font of ``char_widths``."""
  return max(
    sum(char_widths[min(ord(char), len(char_widths) - 1)] for char in line)
    for line in text.split("\n")
  )


def overlay_width(labels: str, values: str, char_widths: Sequence[int]) -> int:
  """How far (pixels) a text overlay of ``labels`` and ``values`` reaches in from its edge."""
  width = OVERLAY_EDGE_PX + _text_width(labels, char_widths)
  return width + (OVERLAY_GAP_PX + _text_width(values, char_widths) if values else 0)


def _wrap(text: str, width: int, char_widths: Sequence[int]) -> str:
  """``text`` broken between words into lines whose overlays fit in ``width`` pixels (a word
  longer than that keeps a line of its own)."""
  lines = []
  for word in text.split():
    if lines and overlay_width(f"{lines[-1]} {word}", "", char_widths) <= width:
      lines[-1] = f"{lines[-1]} {word}"
    else:
      lines.append(word)
  return "\n".join(lines)


def _subsample(count: int, limit: int) -> np.ndarray:
  """At most ``limit`` indices spread evenly over ``range(count)``, first and last included."""
  return np.unique(np.linspace(0, count - 1, min(count, limit)).round().astype(int))


def target_rgba(colour: np.ndarray) -> np.ndarray:
  """The colour of a module's current-target marker, from the module's ``colour``."""
  return _tint(colour, _WHITE, 0.25, TARGET_ALPHA)


def target_radius(robot_length: float, arm_radius: float) -> float:
  """Radius (m) of a current-target marker on an arm of ``robot_length`` and ``arm_radius``."""
  return max(TARGET_RADIUS * robot_length, TARGET_ARM_SHARE * arm_radius)


def add_geom(scene: mujoco.MjvScene, kind: int, size, position, rgba) -> mujoco.MjvGeom | None:
  """Adds a decoration geom to ``scene``; None (nothing added) when the scene is full."""
  if scene.ngeom >= scene.maxgeom:
    return None
  scene.ngeom += 1  # The scene exposes its first ngeom geoms only.
  geom = scene.geoms[scene.ngeom - 1]
  mujoco.mjv_initGeom(
    geom, kind, np.asarray(size, float), np.asarray(position, float), np.eye(3).ravel(), rgba
  )
  geom.category = mujoco.mjtCatBit.mjCAT_DECOR
  return geom


class EpisodeMarkers:
  """The decorations of one episode; ``at(time, tips)`` moves them to a moment, then the object
  is a dm_control ``scene_callback`` that adds them to the scene."""

  def __init__(
    self,
    episode: episodes.Episode,
    colours: np.ndarray,
    robot_length: float,
    arm_radius: float,
    title: str,
  ):
    """``colours``: (num_modules, 4) every module's colour; ``robot_length`` and ``arm_radius``
    (m) scale the markers; ``title``: the caption's first line."""
    self._episode = episode
    self._length = robot_length
    self._target_radius = target_radius(robot_length, arm_radius)
    self._title = title
    scored = np.array(episode.scored_modules) - 1
    self._colours = np.asarray(colours)[scored]
    targets = episode.targets[..., :3]
    # Consecutive repeats (a reach target held all episode) are drawn once.
    self._trails = []
    for module in range(targets.shape[1]):
      keep = np.ones(len(targets), bool)
      keep[1:] = np.any(np.diff(targets[:, module], axis=0) != 0, axis=1)
      trail = targets[keep, module]
      self._trails.append(trail[_subsample(len(trail), MAX_TRAIL_MARKERS)])
    self._errors_mm = metrics.position_error_mm(episode.achieved[..., :3], targets)
    self._starts = episode.poses[0, scored, :3]
    self._path_stride = max(1, int(np.ceil(len(targets) / MAX_PATH_SEGMENTS)))
    self._time = 0.0
    self._tips = self._starts

  @property
  def geom_count(self) -> int:
    """The most scene geoms the decorations add to one frame."""
    path_segments = len(self._errors_mm) // self._path_stride + 1
    return sum(len(trail) + 1 + path_segments for trail in self._trails)

  def at(self, time: float, tips: np.ndarray) -> None:
    """Shows the moment ``time`` (control steps since the start) with the scored modules' tips
    at ``tips`` (m), ``(scored modules, 3)``."""
    self._time = time
    self._tips = np.asarray(tips, dtype=float)

  def _step(self) -> int:
    """The step under way: its target is the one the arm is moving to."""
    return min(int(np.ceil(self._time)) - 1 if self._time > 0 else 0, len(self._errors_mm) - 1)

  def _path(self, module: int) -> np.ndarray:
    """(points, 3) the tip path of ``module`` (index among scored) up to now."""
    done = int(np.floor(self._time + 1e-9))
    stride = self._path_stride
    reached = self._episode.achieved[stride - 1 : done : stride, module, :3]
    return np.concatenate([self._starts[None, module], reached, self._tips[None, module]])

  def __call__(self, physics, scene: mujoco.MjvScene) -> None:
    del physics  # The markers come from the episode; the arm is already in the scene.
    step = self._step()
    current = self._episode.targets[step, :, :3]
    add = functools.partial(add_geom, scene)
    sphere = mujoco.mjtGeom.mjGEOM_SPHERE
    for module, colour in enumerate(self._colours):
      trail_rgba = _tint(colour, _WHITE, 0.45, TRAIL_ALPHA)
      for point in self._trails[module]:
        add(sphere, (TRAIL_RADIUS * self._length,) * 3, point, trail_rgba)
      add(sphere, (self._target_radius,) * 3, current[module], target_rgba(colour))
      path = self._path(module)
      path_rgba = _tint(colour, np.zeros(4), 0.35, 1.0)
      for start, end in zip(path[:-1], path[1:]):
        if np.array_equal(start, end):
          continue
        geom = add(mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), start, path_rgba)
        if geom is not None:
          mujoco.mjv_connector(
            geom, mujoco.mjtGeom.mjGEOM_CAPSULE, PATH_RADIUS * self._length, start, end
          )

  def caption(
    self, height: int, width: int, char_widths: Sequence[int]
  ) -> tuple[engine.TextOverlay, ...]:
    """The title (top left, wrapped to the frame's width), the step with the mean tip error of
    the scored modules after it (bottom right) and, where it fits beside them, a legend (bottom
    left), for frames of ``height`` x ``width`` pixels (none if small). ``char_widths``: pixel
    width of each ASCII character in the overlay font (``MjrContext.charWidth``)."""
    if height < MIN_CAPTION_HEIGHT:
      return ()
    steps = len(self._errors_mm)
    done = int(np.floor(self._time + 1e-9))
    error = f"{self._errors_mm[done - 1].mean():.1f} mm" if done else "-"
    status_labels = "step\nmean tip error"
    widest_status = f"{steps} of {steps}\n{self._errors_mm.mean(axis=1).max():.1f} mm"
    legend = ("dots\nline", "target\ntip path")
    overlays = [
      engine.TextOverlay(
        _wrap(self._title, width, char_widths), "", style="normal", position="top left"
      ),
      engine.TextOverlay(
        status_labels, f"{done} of {steps}\n{error}", style="normal", position="bottom right"
      ),
    ]
    if (
      overlay_width(*legend, char_widths) + overlay_width(status_labels, widest_status, char_widths)
      <= width
    ):
      overlays.append(engine.TextOverlay(*legend, style="normal", position="bottom left"))
    return tuple(overlays)
