"""Renders a replayed episode to an MP4 (or to frames) off-screen, choosing the OpenGL backend.

The backend named by ``MUJOCO_GL`` (``egl`` unless set otherwise; softbench sets it on import)
is tried first, then ``egl``, then ``osmesa``; each try is a fresh child process
(``softbench.rendering.worker``), because dm_control binds its backend on first import. When
none works the error says what to install.
"""

import dataclasses
import json
import os
import pathlib
import pickle
import subprocess
import sys
import tempfile
import time

from rich.progress import Progress

from softbench import progress as progress_bars
from softbench.rendering import options as video_options
from softbench.rendering import replay as episode_replay
from softbench.rendering import worker

OFFSCREEN_BACKENDS = ("egl", "osmesa")
INSTALL_HINTS = {
  "egl": "EGL (Debian/Ubuntu: apt-get install libegl1 libgl1-mesa-dri)",
  "osmesa": "OSMesa (Debian/Ubuntu: apt-get install libosmesa6)",
}


class RenderingUnavailable(RuntimeError):
  """No OpenGL backend can render off-screen on this machine."""


class RenderingFailed(RuntimeError):
  """A backend that opened failed while rendering (its message in one line)."""


@dataclasses.dataclass(frozen=True)
class VideoStats:
  """What a render produced.

  Attributes:
    path: The file written.
    frames: Frames rendered.
    backend: The OpenGL backend that rendered them (dm_control's name, e.g. ``egl``).
    render_seconds: Wall time of replaying and rendering (s), without process start.
    total_seconds: Wall time of the whole call (s).
    size_bytes: Size of the file written.
  """

  path: pathlib.Path
  frames: int
  backend: str
  render_seconds: float
  total_seconds: float
  size_bytes: int

  @property
  def frames_per_second(self) -> float:
    return self.frames / self.render_seconds if self.render_seconds > 0 else float("inf")

  def describe(self, options: video_options.VideoOptions) -> str:
    """One line: the file, its frames, size and how fast it was rendered with ``options``."""
    return (
      f"video: {self.path} ({self.frames} frames, {options.width}x{options.height} at "
      f"{options.fps:g} fps, {self.frames / options.fps:.1f} s, "
      f"{self.size_bytes / 1024:.0f} KiB); rendered with {self.backend} in "
      f"{self.render_seconds:.1f} s ({self.frames_per_second:.1f} frames/s)"
    )


def backend_candidates() -> tuple[str, ...]:
  """Backends to try, in order: ``MUJOCO_GL`` if set, then ``OFFSCREEN_BACKENDS``."""
  chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
  return tuple(dict.fromkeys(([chosen] if chosen else []) + list(OFFSCREEN_BACKENDS)))


def _child_environment(backend: str) -> dict:
  environment = dict(os.environ, MUJOCO_GL=backend)
  # PyOpenGL must load the same platform as the context (dm_control sets it when unset).
  environment.pop("PYOPENGL_PLATFORM", None)
  return environment


def _last_line(text: str) -> str:
  lines = [line.strip() for line in text.splitlines() if line.strip()]
  return lines[-1] if lines else "no message"


def _render_in_child(request: dict, backend: str, progress: Progress, bar) -> tuple[dict, bool]:
  """Runs the worker with ``backend``: (its result, whether the backend opened)."""
  with tempfile.TemporaryDirectory(prefix="softbench-render-") as folder:
    request_path = pathlib.Path(folder) / "request.pickle"
    result_path = pathlib.Path(folder) / "result.json"
    request_path.write_bytes(pickle.dumps(request))
    with open(pathlib.Path(folder) / "stderr.txt", "w+") as errors:
      child = subprocess.Popen(
        [sys.executable, "-m", worker.__name__, str(request_path), str(result_path)],
        stdout=subprocess.PIPE,
        stderr=errors,
        text=True,
        env=_child_environment(backend),
      )
      ready = False
      try:
        for line in child.stdout:
          if line.startswith(worker.READY):
            ready = True
          elif line.startswith(worker.FRAME):
            progress.update(bar, completed=int(line.split()[1]))
        child.wait()
      finally:
        if child.poll() is None:  # Interrupted: stop the child, leave no partial file.
          child.terminate()
          child.wait()
      errors.seek(0)
      stderr = errors.read()
    result = json.loads(result_path.read_text()) if result_path.exists() else {}
  if child.returncode == 0:
    return result, True
  message = result.get("error") or _last_line(stderr)
  if not ready:
    return {"error": message}, False
  raise RenderingFailed(f"rendering with {backend} failed: {message}")


def render(
  replay: episode_replay.Replay,
  output: str | os.PathLike,
  options: video_options.VideoOptions = video_options.VideoOptions(),
  show_progress: bool = False,
) -> VideoStats:
  """Writes the frames of ``replay`` to ``output``: an ``.mp4`` video (H.264, ``options.fps``)
  or an ``.npy`` array (frames, height, width, 3) of uint8.

  Raises:
    ValueError: an output path that cannot be written (one line).
    RenderingUnavailable: no OpenGL backend works; the message says what to install.
    RuntimeError: rendering failed after the backend opened.
  """
  started = time.perf_counter()
  output = pathlib.Path(output)
  if output.suffix != ".npy":
    video_options.check_video_path(output)
  request = {"replay": replay, "options": options, "output": str(output.absolute())}
  failures = {}
  progress = progress_bars.counting(show_progress, transient=True)
  with progress:
    for backend in backend_candidates():
      bar = progress.add_task(
        f"rendering {output.name} ({backend})", total=options.frame_count(replay.steps)
      )
      result, opened = _render_in_child(request, backend, progress, bar)
      if opened:
        return VideoStats(
          output,
          result["frames"],
          result["backend"],
          result["render_seconds"],
          time.perf_counter() - started,
          output.stat().st_size,
        )
      failures[backend] = result["error"]
      progress.remove_task(bar)
  tried = "; ".join(f"{backend}: {error}" for backend, error in failures.items())
  install = " or ".join(INSTALL_HINTS.values())
  raise RenderingUnavailable(
    f"no OpenGL backend can render off-screen here ({tried}); install "
    f"{install}, or set MUJOCO_GL to a backend that works"
  )
