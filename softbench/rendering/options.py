"""What a video looks like (size, frame rate, camera, frames per control step), checked up front
(``from_text`` reads them from a command line), and where it may be written: bad input is
refused before anything runs."""

import dataclasses
import math
import numbers
import os
import pathlib

from softbench import storage

DEFAULT_WIDTH = 640  # (pixels)
DEFAULT_HEIGHT = 480  # (pixels)
DEFAULT_FPS = 30.0  # (frames/s)
MIN_SIZE = 16  # (pixels) Smallest width or height.
MAX_SIZE = 4096  # (pixels) Largest width or height (the off-screen buffer grows to the request).
MAX_FPS = 240.0  # (frames/s)
MAX_FRAMES_PER_STEP = 100  # Frames within one control period (registered robots: 200 or more
# physics steps per period; the replay refuses more frames than steps).
CAMERAS = ("workspace", "front", "side", "below")
"""Named cameras of every rendered scene, each framing the whole episode: ``workspace`` an
oblique view from above, ``front`` along world +y, ``side`` along world -x, ``below`` straight
up from under the arm (the xy-plane)."""
DEFAULT_CAMERA = "workspace"
VIDEO_SUFFIX = ".mp4"


@dataclasses.dataclass(frozen=True)
class VideoOptions:
  """How to render an episode.

  Attributes:
    width, height: Frame size (pixels); even, as H.264 (yuv420p) needs.
    fps: Frames per second of the video.
    camera: One of ``CAMERAS``.
    frames_per_step: Frames rendered within each control period (evenly spaced, the last at its
      end); 1 shows the pose at the end of every control step, more show the motion between.
  """

  width: int = DEFAULT_WIDTH
  height: int = DEFAULT_HEIGHT
  fps: float = DEFAULT_FPS
  camera: str = DEFAULT_CAMERA
  frames_per_step: int = 1

  def __post_init__(self):
    for name in ("width", "height"):
      value = getattr(self, name)
      if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Integral)
        or not MIN_SIZE <= value <= MAX_SIZE
        or value % 2
      ):
        raise ValueError(
          f"{name} must be an even number of pixels from {MIN_SIZE} to {MAX_SIZE}, got {value!r}"
        )
    if (
      isinstance(self.fps, bool)
      or not isinstance(self.fps, numbers.Real)
      or not math.isfinite(self.fps)
      or not 0 < self.fps <= MAX_FPS
    ):
      raise ValueError(f"fps must be a number above 0 and at most {MAX_FPS:g}, got {self.fps!r}")
    if self.camera not in CAMERAS:
      raise ValueError(f"unknown camera {self.camera!r}; choose one of {', '.join(CAMERAS)}")
    if (
      isinstance(self.frames_per_step, bool)
      or not isinstance(self.frames_per_step, numbers.Integral)
      or not 1 <= self.frames_per_step <= MAX_FRAMES_PER_STEP
    ):
      raise ValueError(
        f"frames per step must be an integer from 1 to {MAX_FRAMES_PER_STEP}, "
        f"got {self.frames_per_step!r}"
      )

  def frame_count(self, steps: int) -> int:
    """Frames of an episode of ``steps`` control steps: the start, then frames_per_step each."""
    return 1 + steps * self.frames_per_step


def parse_number(name: str, text: str, kind: type) -> int | float:
  """``text`` (a command line's) as a number of type ``kind``; a one-line ValueError naming
  ``name`` otherwise."""
  try:
    return kind(text)
  except ValueError:
    raise ValueError(f"{name} must be a number, got {text!r}") from None


def from_text(**given: str | None) -> VideoOptions:
  """Checked ``VideoOptions`` from command-line text, by field name (``width="640"``); a field
  given as None keeps its default.

  Raises:
    ValueError: a field that is not a number where one is needed, or out of range (one line).
  """
  kinds = {field.name: field.type for field in dataclasses.fields(VideoOptions)}
  return VideoOptions(
    **{
      name: text if kinds[name] is str else parse_number(name.replace("_", " "), text, kinds[name])
      for name, text in given.items()
      if text is not None
    }
  )


def check_video_path(path: str | os.PathLike) -> pathlib.Path:
  """``path`` as a ``Path``, if a video can be written there (missing folders are made later).

  Raises:
    ValueError: not an ``.mp4`` file name, an existing folder, or a place that cannot be written
      (one line).
  """
  path = pathlib.Path(path)
  if path.suffix.lower() != VIDEO_SUFFIX:
    raise ValueError(f"video file must end in {VIDEO_SUFFIX}, got {str(path)!r}")
  return storage.check_writable(path, "video")
