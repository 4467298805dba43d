"""Videos: options and paths refused up front, cameras that frame the episode, scene markers,
the replay check, frames that show a moving arm, MP4s that decode, the backend fallback, and
``softbench render`` / ``softbench run --video``."""

import imageio_ffmpeg
import mujoco
import numpy as np
import pytest

import softbench
from softbench import agents
from softbench import cli
from softbench import robots
from softbench import suite
from softbench.rendering import markers
from softbench.rendering import options
from softbench.rendering import replay
from softbench.rendering import scene
from softbench.rendering import video
from softbench.runners import evaluation

SMALL = options.VideoOptions(width=64, height=48)


@pytest.fixture(autouse=True)
def shared_home(tmp_path_factory, monkeypatch):
  """One data home for the rendering and plot tests: references are traced once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "rendering_home"))


def recorded(robot="tendon-2", task="circle", agent="random", seed=0, **task_options):
  task_options = task_options or {"length": 3}
  env = suite.load(robot, task, seed=seed, **task_options)
  episode = evaluation.run_episode(env, agents.make(agent, robot, seed, "tiny"), task)
  return replay.Replay(robots.make(robot), task, seed, task_options, episode, "test episode")


@pytest.mark.parametrize(
  "fields,message",
  [
    ({"width": 641}, "even number"),
    ({"height": 0}, "even number"),
    ({"width": 8192}, "even number"),
    ({"width": 64.0}, "even number"),
    ({"fps": 0}, "fps must be"),
    ({"fps": float("nan")}, "fps must be"),
    ({"fps": 1000}, "fps must be"),
    ({"camera": "nope"}, "unknown camera"),
    ({"frames_per_step": 0}, "frames per step"),
  ],
)
def test_bad_options_are_refused(fields, message):
  with pytest.raises(ValueError, match=message):
    options.VideoOptions(**fields)


def test_video_paths_are_checked(tmp_path):
  assert options.check_video_path(tmp_path / "new" / "folder" / "a.mp4").suffix == ".mp4"
  (tmp_path / "file.txt").write_text("")
  for path, message in [
    (tmp_path / "a.avi", "must end in .mp4"),
    (tmp_path / "file.txt" / "a.mp4", "is not a folder"),
  ]:
    with pytest.raises(ValueError, match=message):
      options.check_video_path(path)
  (tmp_path / "folder.mp4").mkdir()
  with pytest.raises(ValueError, match="it is a folder"):
    options.check_video_path(tmp_path / "folder.mp4")


@pytest.mark.parametrize("camera", options.CAMERAS)
@pytest.mark.parametrize("aspect", [4 / 3, 0.5])
def test_cameras_frame_every_point(camera, aspect):
  points = np.random.default_rng(0).normal(size=(200, 3)) * [0.05, 0.08, 0.03] + [0, 0, -0.1]
  padding = 0.004
  position, quaternion = scene.camera_pose(camera, points, padding, aspect)
  rotation = np.empty(9)
  mujoco.mju_quat2Mat(rotation, quaternion)
  local = (points - position) @ rotation.reshape(3, 3)  # Camera frame: looks along -z.
  depth = -local[:, 2]
  assert np.all(depth > 0)
  tan_vertical = np.tan(np.radians(scene.FOVY_DEG) / 2)
  assert np.all(np.abs(local[:, 1]) + padding <= depth * tan_vertical)
  assert np.all(np.abs(local[:, 0]) + padding <= depth * tan_vertical * aspect)
  # Framed tightly: some point is near an edge of the picture.
  share = (
    np.maximum(np.abs(local[:, 1]) / tan_vertical, np.abs(local[:, 0]) / tan_vertical / aspect)
    / depth
  )
  assert share.max() > 0.7


UNIFORM_FONT = [10] * 127  # (pixels) A font whose every character is 10 pixels wide.


def test_markers_draw_the_trail_the_target_and_the_path_so_far():
  source = recorded(length=5)
  model = scene.scene_model(source.robot, scene.episode_points(source.episode), 64, 48)
  colours = scene.module_colours(model, source.robot.num_modules)
  assert len({tuple(colour) for colour in colours}) == source.robot.num_modules
  drawn = markers.EpisodeMarkers(
    source.episode, colours, source.robot.length, scene.arm_radius(model), "title"
  )
  counts = []
  for time in (0.0, 2.5, 5.0):
    view = mujoco.MjvScene(model, maxgeom=drawn.geom_count)
    tips = source.episode.poses[int(np.ceil(time)), :, :3]
    drawn.at(time, tips)
    drawn(None, view)
    counts.append(view.ngeom)
    assert all(view.geoms[i].category == mujoco.mjtCatBit.mjCAT_DECOR for i in range(view.ngeom))
  # Per module: 5 trail markers, the current target and a path segment per step so far (at 2.5
  # steps: start -> step 1 -> step 2 -> the tip now).
  assert counts == [2 * (5 + 1), 2 * (5 + 1 + 3), 2 * (5 + 1 + 5)]
  assert max(counts) <= drawn.geom_count


def test_long_trails_and_paths_are_subsampled(monkeypatch):
  source = recorded(length=5)
  monkeypatch.setattr(markers, "MAX_TRAIL_MARKERS", 3)
  monkeypatch.setattr(markers, "MAX_PATH_SEGMENTS", 2)
  model = scene.scene_model(source.robot, scene.episode_points(source.episode), 64, 48)
  drawn = markers.EpisodeMarkers(
    source.episode,
    scene.module_colours(model, 2),
    source.robot.length,
    scene.arm_radius(model),
    "title",
  )
  view = mujoco.MjvScene(model, maxgeom=drawn.geom_count)
  drawn.at(5.0, source.episode.poses[5, :, :3])
  drawn(None, view)
  # Per module: 3 trail markers, the target, and the path start -> step 3 -> step 5.
  assert view.ngeom == 2 * (3 + 1 + 2) <= drawn.geom_count
  assert drawn.caption(480, 640, UNIFORM_FONT) and not drawn.caption(48, 64, UNIFORM_FONT)


@pytest.mark.parametrize("width,legend", [(320, False), (480, None), (640, None), (1280, True)])
def test_caption_fits_the_frame_width(width, legend):
  """The caption's boxes stay inside the frame and apart; None: legend kept only if it fits."""
  source = recorded(length=5)
  model = scene.scene_model(source.robot, scene.episode_points(source.episode), 64, 48)
  title = "reference on spiral (tendon-3) seed 0, paper profile"
  drawn = markers.EpisodeMarkers(
    source.episode,
    scene.module_colours(model, 2),
    source.robot.length,
    scene.arm_radius(model),
    title,
  )
  drawn.at(5.0, source.episode.poses[5, :, :3])
  caption = {overlay.position: overlay for overlay in drawn.caption(360, width, UNIFORM_FONT)}
  top = caption[mujoco.mjtGridPos.mjGRID_TOPLEFT]
  assert top.title.split() == title.split()  # Every word, wrapped between words only.
  assert all(
    markers.overlay_width(line, "", UNIFORM_FONT) <= width for line in top.title.split("\n")
  )
  bottom = [
    caption[position]
    for position in (mujoco.mjtGridPos.mjGRID_BOTTOMLEFT, mujoco.mjtGridPos.mjGRID_BOTTOMRIGHT)
    if position in caption
  ]
  assert (
    sum(markers.overlay_width(overlay.title, overlay.body, UNIFORM_FONT) for overlay in bottom)
    <= width
  )
  if legend is not None:
    assert (len(bottom) == 2) == legend


def test_replay_reproduces_the_episode_and_refuses_another_seed():
  source = recorded(agent="random")
  times = [time for time, _ in replay.moments(source, frames_per_step=3)]
  np.testing.assert_allclose(times, np.arange(0, 3 + 1e-9, 1 / 3))
  other = replay.Replay(source.robot, source.task, 1, source.task_options, source.episode, "")
  with pytest.raises(RuntimeError, match="left the recorded episode at control step 0"):
    list(replay.moments(other, 1))


def test_frames_show_the_arm_moving_with_the_first_backend_that_works(monkeypatch, tmp_path):
  source = recorded(robot="tendon-2", task="circle", agent="random", length=3)
  monkeypatch.setenv("MUJOCO_GL", "no-such-backend")  # Fails; egl or osmesa takes over.
  assert video.backend_candidates()[0] == "no-such-backend"
  stats = video.render(
    source, tmp_path / "frames.npy", options.VideoOptions(width=96, height=72, frames_per_step=2)
  )
  assert stats.backend in video.OFFSCREEN_BACKENDS
  frames = np.load(stats.path)
  assert frames.shape == (1 + 3 * 2, 72, 96, 3) and frames.dtype == np.uint8
  for frame in frames:  # Not blank: many colours, and far from uniform.
    assert frame.std() > 10 and len(np.unique(frame.reshape(-1, 3), axis=0)) > 50
  # The arm moves from step to step, and within the first half of every step (it has mostly
  # settled by the second half).
  for earlier, later in zip(frames[:-1:2], frames[1::2]):
    assert np.abs(earlier.astype(int) - later).mean() > 0.5
  for earlier, later in zip(frames[:-2:2], frames[2::2]):
    assert np.abs(earlier.astype(int) - later).mean() > 0.5
  # The camera frames the arm: it is drawn away from the edges (module 1 is red-orange).
  red = (frames[..., 0] > 150) & (frames[..., 1] < 120) & (frames[..., 2] < 110)
  assert red[:, 8:-8, 8:-8].any(axis=(1, 2)).all()
  monkeypatch.setattr(video, "OFFSCREEN_BACKENDS", ())
  with pytest.raises(video.RenderingUnavailable, match="no-such-backend.*libegl1.*libosmesa6"):
    video.render(source, tmp_path / "frames.npy", SMALL)


RENDER = [
  "render",
  "--task",
  "circle",
  "--agent",
  "zero",
  "--robot",
  "tendon-2",
  "--profile",
  "tiny",
  "--width",
  "64",
  "--height",
  "48",
]


def test_cli_render_writes_an_mp4_that_decodes(tmp_path, capsys):
  out = tmp_path / "videos" / "zero.mp4"
  assert cli.main([*RENDER, "--out", str(out), "--fps", "10", "--camera", "side"]) == 0
  assert f"video: {out} (5 frames, 64x48 at 10 fps" in capsys.readouterr().out
  reader = imageio_ffmpeg.read_frames(str(out))
  metadata = next(reader)
  frames = list(reader)
  assert len(frames) == options.VideoOptions().frame_count(4) == 5  # Tiny profile: 4 steps.
  assert metadata["size"] == (64, 48) and metadata["fps"] == pytest.approx(10)
  assert [p.name for p in out.parent.iterdir()] == ["zero.mp4"]  # No temporary file left.


@pytest.mark.skipif(
  "osmesa" not in softbench.installed_headless_backends(),
  reason="OSMesa is not installed (Debian: libosmesa6)",
)
def test_cli_render_falls_back_to_osmesa_when_egl_cannot_open(tmp_path, launch_with_broken_egl):
  out = tmp_path / "zero.mp4"
  result = launch_with_broken_egl([*RENDER, "--out", str(out)])
  assert result.returncode == 0, result.stderr
  assert "rendered with osmesa" in result.stdout
  assert imageio_ffmpeg.count_frames_and_secs(str(out))[0] == 5


@pytest.mark.parametrize(
  "extra,message",
  [
    (["--width", "641"], "even number"),
    (["--width", "wide"], "width must be a number"),
    (["--height", "0"], "even number"),
    (["--fps", "0"], "fps must be"),
    (["--camera", "nope"], "unknown camera"),
    (["--frames-per-step", "0"], "frames per step"),
    (["--seed", "-1"], "seed must be"),
  ],
)
def test_cli_render_refuses_bad_input_with_one_line(extra, message, tmp_path, capsys):
  assert cli.main([*RENDER, "--out", str(tmp_path / "a.mp4"), *extra]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0]


@pytest.mark.parametrize(
  "out,message", [("a.gif", "must end in .mp4"), ("file.txt/a.mp4", "is not a folder")]
)
def test_cli_refuses_unwritable_video_paths(out, message, tmp_path, capsys):
  (tmp_path / "file.txt").write_text("")
  for argv in (
    [*RENDER, "--out", str(tmp_path / out)],
    [
      "run",
      "--task",
      "circle",
      "--agent",
      "zero",
      "--profile",
      "tiny",
      "--results",
      str(tmp_path),
      "--video",
      str(tmp_path / out),
    ],
  ):
    assert cli.main(argv) == cli.EXIT_USAGE
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0]
  assert not list(tmp_path.glob("*.json"))


def test_a_backend_failing_while_rendering_is_one_line(tmp_path, capsys, monkeypatch):
  def failing(*args, **kwargs):
    raise video.RenderingFailed("rendering with egl failed: GL context lost")

  monkeypatch.setattr(video, "render", failing)
  assert cli.main([*RENDER, "--out", str(tmp_path / "a.mp4")]) == cli.EXIT_FAILURE
  lines = capsys.readouterr().err.strip().splitlines()
  assert lines[-1] == "softbench: error: rendering with egl failed: GL context lost"
  assert not any(line.startswith("Traceback") for line in lines)
