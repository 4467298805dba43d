"""The child process that renders: ``python -m softbench.rendering.worker REQUEST RESULT``.

dm_control binds its OpenGL backend (``MUJOCO_GL``) when it is first imported, so each backend
is tried in a fresh process (``softbench.rendering.video``). The child first opens an off-screen
context and prints ``ready``; a failure before that means the backend does not work here (exit
``EXIT_NO_BACKEND``). Then it renders the frames of the pickled request, printing ``frame <n>``
after each, writes them to the requested ``.mp4`` (H.264 through mediapy and the ffmpeg binary of
imageio-ffmpeg) or ``.npy`` file through a temporary file and a rename, and writes a JSON result.
"""

import json
import os
import pathlib
import pickle
import signal
import sys
import time
import traceback

EXIT_NO_BACKEND = 3
EXIT_TERMINATED = 143  # 128 + SIGTERM, as shells report it.
READY = "ready"
FRAME = "frame"
CRF = 20  # H.264 constant rate factor: lower is better quality and larger files.


def _open_backend() -> str:
  """Opens and frees a small off-screen context; returns dm_control's backend name."""
  from dm_control import _render  # pylint: disable=import-outside-toplevel

  context = _render.Renderer(max_width=16, max_height=16)
  context.free()
  return _render.BACKEND


def _temporary(path: pathlib.Path) -> pathlib.Path:
  """A file beside ``path`` with the same suffix (ffmpeg picks the container by suffix)."""
  return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


def _render(request: dict) -> dict:
  import imageio_ffmpeg  # pylint: disable=import-outside-toplevel
  import mediapy  # pylint: disable=import-outside-toplevel
  import numpy as np  # pylint: disable=import-outside-toplevel

  from softbench.rendering import frames  # pylint: disable=import-outside-toplevel

  options, output = request["options"], pathlib.Path(request["output"])
  episode_frames = frames.EpisodeFrames(request["replay"], options)
  output.parent.mkdir(parents=True, exist_ok=True)
  partial = _temporary(output)
  started = time.perf_counter()
  count = 0
  try:
    if output.suffix == ".npy":
      images = []
      for image in episode_frames.frames():
        images.append(image)
        count += 1
        print(FRAME, count, flush=True)
      np.save(partial, np.stack(images))
    else:
      mediapy.set_ffmpeg(imageio_ffmpeg.get_ffmpeg_exe())
      with mediapy.VideoWriter(
        partial, (options.height, options.width), fps=options.fps, codec="h264", crf=CRF
      ) as writer:
        for image in episode_frames.frames():
          writer.add_image(image)
          count += 1
          print(FRAME, count, flush=True)
    os.replace(partial, output)
  finally:
    partial.unlink(missing_ok=True)
  return {"frames": count, "render_seconds": time.perf_counter() - started}


def main(argv: list[str]) -> int:
  request_path, result_path = map(pathlib.Path, argv)
  # Stopped by the parent (Ctrl-C there): unwind, so that no temporary file is left.
  signal.signal(signal.SIGTERM, lambda *_: sys.exit(EXIT_TERMINATED))
  try:
    backend = _open_backend()
  except Exception as error:  # pylint: disable=broad-except
    # Any failure to load or open the backend means: this backend does not work here.
    message = str(error).strip().splitlines()[-1] if str(error).strip() else ""
    result_path.write_text(json.dumps({"error": f"{type(error).__name__}: {message}"}))
    return EXIT_NO_BACKEND
  print(READY, flush=True)
  try:
    with open(request_path, "rb") as file:
      request = pickle.load(file)
    result = {"backend": backend, **_render(request)}
  except Exception as error:  # pylint: disable=broad-except
    traceback.print_exc()
    result_path.write_text(json.dumps({"error": f"{type(error).__name__}: {error}"}))
    return 1
  result_path.write_text(json.dumps(result))
  return 0


if __name__ == "__main__":
  sys.exit(main(sys.argv[1:]))
