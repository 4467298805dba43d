"""Plots: run plots next to the result record, the forgetting heat map, ``softbench run
--video``."""

import json

import imageio_ffmpeg
from matplotlib import image
import numpy as np
import pytest

from softbench import agents
from softbench import cli
from softbench import plots
from softbench import records
from softbench import suite
from softbench.runners import evaluation


@pytest.fixture(autouse=True)
def shared_home(tmp_path_factory, monkeypatch):
  """One data home for the rendering and plot tests: references are traced once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "rendering_home"))


def episode(robot, task, seed, **task_options):
  env = suite.load(robot, task, seed=seed, **task_options)
  return evaluation.run_episode(env, agents.make("random", robot, seed, "tiny"), task)


def png_size(path):
  with open(path, "rb") as file:
    assert file.read(8) == b"\x89PNG\r\n\x1a\n"
  return image.imread(path).shape[:2]


def test_run_plots_are_saved_next_to_the_record(tmp_path):
  episodes = [episode("tendon-2", "circle", seed, length=5) for seed in range(2)]
  record = {"agent": "random", "task": "circle", "robot": "tendon-2", "profile": "tiny"}
  written = plots.save_run_plots(tmp_path / "run.json", record, episodes)
  assert [path.name for path in written] == ["run-paths.png", "run-error.png"]
  for path in written:
    height, width = png_size(path)
    assert height > 200 and width > 400


def test_reach_paths_and_errors_are_plotted(tmp_path):
  reach = episode("pneumatic-433", "reach", 0, steps=3)  # Position-only target, one module.
  assert png_size(plots.tracking_paths(reach, tmp_path / "paths.png"))[0] > 200
  assert png_size(plots.tracking_errors([reach], tmp_path / "errors.png"))[0] > 200
  with pytest.raises(ValueError, match="no episodes"):
    plots.tracking_errors([], tmp_path / "none.png")


def test_forgetting_matrix_is_a_heat_map_with_unseen_entries(tmp_path):
  configurations = [f"tendon-{k}" for k in range(1, 6)]
  matrix = np.full((5, 5), np.nan)
  for stage in range(5):
    matrix[stage, : stage + 1] = np.linspace(1.0, 4.0, stage + 1)
  path = plots.forgetting_matrix(matrix, configurations, tmp_path / "forgetting.png")
  assert png_size(path)[1] > png_size(path)[0] > 200


@pytest.mark.parametrize(
  "matrix,configurations,message",
  [
    (np.ones(3), ["a", "b", "c"], "must be \\(stages, configurations\\)"),
    (np.ones((2, 3)), ["a", "b"], "3 columns but 2 configurations"),
    (np.full((2, 2), np.nan), ["a", "b"], "no evaluated entry"),
    (np.array([[1.0, -1.0]]), ["a", "b"], "non-negative"),
    (np.array([[1.0, np.inf]]), ["a", "b"], "finite"),
  ],
)
def test_forgetting_matrix_refuses_bad_input(matrix, configurations, message, tmp_path):
  with pytest.raises(ValueError, match=message):
    plots.forgetting_matrix(matrix, configurations, tmp_path / "bad.png")
  assert not list(tmp_path.iterdir())


def test_softbench_run_saves_plots_and_a_video(tmp_path, capsys):
  results = tmp_path / "results"
  video = tmp_path / "run.mp4"
  argv = [
    "run",
    "--task",
    "circle",
    "--agent",
    "zero",
    "--robot",
    "tendon-2",
    "--profile",
    "tiny",
    "--seeds",
    "1",
    "--results",
    str(results),
    "--video",
    str(video),
    "--width",
    "64",
    "--height",
    "48",
  ]
  assert cli.main(argv) == 0
  out = capsys.readouterr().out
  (record_path,) = results.glob("*.json")
  assert json.loads(record_path.read_text())["seeds"] == 1
  stem = record_path.with_suffix("")
  for suffix in ("-paths.png", "-error.png"):
    path = stem.with_name(stem.name + suffix)
    assert f"plot: {path}" in out and png_size(path)[0] > 100
  assert f"video: {video} (5 frames" in out
  assert imageio_ffmpeg.count_frames_and_secs(str(video))[0] == 5
  assert records.read(record_path)["video"] == "../run.mp4"  # Relative to the record's folder.
  pages = tmp_path / "pages"
  assert cli.main(["leaderboard", "--results", str(results), "--write", "--out", str(pages)]) == 0
  assert "[video](<../run.mp4>)" in (pages / "README.md").read_text()
