"""Exp1S in physics (``softbench run --protocol exp1s``) on a two-stage sequence, tiny profile."""

import json

import numpy as np
import pytest
import torch

from softbench import cli
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import storage
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import checkpoints
from softbench.runners import continual


def test_exp1s_end_to_end(two_stages, tmp_path, capsys):
  # On the default family; test_sweep runs Exp1S on tendon-local end to end (record, heat map).
  results, family = tmp_path / "results", continual.DEFAULT_FAMILY
  argv = [
    "run",
    "--protocol",
    "exp1s",
    "--agent",
    "smpl",
    "--profile",
    "tiny",
    "--seeds",
    "1",
    "--results",
    str(results),
    "--family",
    family,
  ]
  stages = [f"{family}-{robots.make(name).num_modules}" for name in two_stages]
  assert cli.main(argv) == 0
  out = capsys.readouterr().out
  for heading in (
    "closed loop, position (mm)",
    "open loop, position (mm)",
    "closed loop, normalised tip error (%)",
    "forgetting matrix",
  ):
    assert heading in out
  (path,) = results.glob("smpl-exp1s-tiny-*.json")
  assert path.with_name(f"{path.stem}-forgetting.png").stat().st_size > 0
  record = records.read(path)  # Checked: schema, integrity hash, consistency.
  assert record == json.loads(path.read_text()) and record["version"] == continual.RECORD_VERSION
  assert record["robots"] == stages and record["seeds"] == 1
  (seed,) = record["per_seed"]
  for loop in continual.LOOPS:
    for task in continual.TASKS:
      entries = seed["scores"][loop][task]
      assert len(entries) == len(stages)
      assert all(np.isfinite(entry[name]) for entry in entries for name in continual.METRICS)
  matrix = seed["forgetting_tip_percent"]
  assert matrix[0][1] is None and matrix[1][0] == matrix[0][0]
  closed_spiral = [entry["normalised_tip_percent"] for entry in seed["scores"]["closed"]["spiral"]]
  assert matrix[1] == closed_spiral
  model_level = seed["forgetting_model_pose_mse"]
  assert model_level[1][0] == model_level[0][0] and model_level[0][1] is None
  assert not continual.finished_seeds_folder(profiles.get("tiny"), family).exists()
  # The second run reuses the cached network and gives the same scores.
  again = tmp_path / "again.json"
  assert cli.main([*argv, "--json", str(again)]) == 0
  assert json.loads(again.read_text())["per_seed"] == record["per_seed"]


def test_forgetting_is_detected():
  matrix = np.array([[0.5, np.nan], [0.5, 0.2]])
  continual.check_no_forgetting(matrix)
  matrix[1, 0] = np.nextafter(0.5, 1.0)
  with pytest.raises(continual.ForgettingDetected, match="configuration 1 changed after stage 2"):
    continual.check_no_forgetting(matrix)


def test_detected_forgetting_is_one_line_and_a_failure(two_stages, monkeypatch, tmp_path, capsys):
  changed = np.array([[0.5, np.nan], [0.25, 0.2]])
  monkeypatch.setattr(
    continual, "run_seed", lambda *arguments: continual.check_no_forgetting(changed)
  )
  argv = [
    "run",
    "--protocol",
    "exp1s",
    "--agent",
    "smpl",
    "--profile",
    "tiny",
    "--seeds",
    "1",
    "--results",
    str(tmp_path / "results"),
  ]
  assert cli.main(argv) == cli.EXIT_FAILURE
  errors = capsys.readouterr().err
  assert "Traceback" not in errors
  error = errors.strip().splitlines()[-1]  # After the collection's progress bars.
  assert error.startswith("softbench: error: configuration 1 changed after stage 2: 0.5 -> 0.25")
  assert not (tmp_path / "results").exists()


@pytest.mark.parametrize(
  "extra,message",
  [
    (["--agent", "lstm"], "takes --agent smpl"),
    (["--agent", "smpl", "--task", "spiral"], "drop --task"),
    (["--agent", "smpl", "--eval", "model"], "drop --eval"),
    (["--agent", "smpl", "--family", "tendon-loc"], "unknown tendon family 'tendon-loc'"),
    (["--agent", "smpl", "--family", "pneumatic"], "unknown tendon family 'pneumatic'"),
  ],
)
def test_exp1s_refuses_bad_input_with_one_line(extra, message, capsys, tmp_path):
  argv = ["run", "--protocol", "exp1s", *extra, "--results", str(tmp_path)]
  assert cli.main(argv) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0]


def test_unknown_protocol_and_missing_task(capsys):
  assert cli.main(["run", "--protocol", "exp9", "--agent", "smpl"]) == cli.EXIT_USAGE
  assert cli.main(["run", "--agent", "smpl"]) == cli.EXIT_USAGE
  assert cli.main(["run", "--task", "spiral", "--agent", "smpl", "--family", "tendon-local"]) == (
    cli.EXIT_USAGE
  )
  lines = capsys.readouterr().err.strip().splitlines()
  assert "unknown protocol" in lines[0] and "needs --task" in lines[1]
  assert "--family goes with --protocol exp1s" in lines[2]


@pytest.mark.parametrize("extra", [["--video", "x.mp4"], ["--fault", "1:0:0.5"], ["--adaptive"]])
def test_exp1s_refuses_per_run_options(extra, capsys, tmp_path):
  argv = ["run", "--protocol", "exp1s", "--agent", "smpl", *extra, "--results", str(tmp_path)]
  assert cli.main(argv) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and f"drop {extra[0]}" in lines[0]


def test_a_damaged_cached_network_is_trained_again(
  two_stages, tmp_path, assert_one_line_retraining
):
  tiny = profiles.get("tiny")
  first = continual.build(0, tiny)
  (path,) = (tmp_path / "home" / checkpoints.CHECKPOINT_FOLDER).glob("exp1s-*.pt")
  path.write_bytes(b"hello")
  with pytest.warns(storage.CorruptFileWarning) as caught:
    again = continual.build(0, tiny)
  assert_one_line_retraining(caught, path)
  first_state, again_state = first.network.state_dict(), again.network.state_dict()
  assert all(torch.equal(first_state[name], again_state[name]) for name in first_state)
  np.testing.assert_array_equal(again.forgetting_pose_mse, first.forgetting_pose_mse)
  np.testing.assert_array_equal(
    continual.build(0, tiny).forgetting_action_mse, first.forgetting_action_mse
  )  # Loaded from the new file.


def test_an_interrupted_exp1s_resumes_from_its_finished_seeds(two_stages, monkeypatch):
  tiny, scored, score_seed = profiles.get("tiny"), [], continual.score_seed

  def counting(seed, profile, show_progress, kept_episodes, family):
    scored.append(seed)
    if seed == 1 and len(scored) == 2:  # The first run stops as seed 1 starts.
      raise KeyboardInterrupt
    return score_seed(seed, profile, show_progress, kept_episodes, family)

  monkeypatch.setattr(continual, "score_seed", counting)
  with pytest.raises(KeyboardInterrupt):
    continual.execute(tiny, seeds=2, show_progress=False, workers=1)
  assert (continual.finished_seeds_folder(tiny) / "seed0.json").exists()
  resumed = continual.execute(tiny, seeds=2, show_progress=False, workers=1)
  assert scored == [0, 1, 1]  # Seed 0 was not scored again.
  assert not continual.finished_seeds_folder(tiny).exists()
  fresh = continual.execute(tiny, seeds=2, show_progress=False, workers=1)
  assert scored == [0, 1, 1, 0, 1]
  assert resumed["per_seed"] == fresh["per_seed"]


def test_a_seed_interrupted_in_its_evaluation_resumes_from_its_finished_episodes(
  two_stages, monkeypatch, capsys
):
  tiny, episodes, run_episode = profiles.get("tiny"), [], continual.evaluation.run_episode
  total = len(two_stages) * len(continual.LOOPS) * len(continual.TASKS)
  finished_before_interruption = 5

  def counting(env, agent, task, show_progress=False):
    if len(episodes) == finished_before_interruption and not resumed:
      raise KeyboardInterrupt
    episodes.append((agent.robot.name, agent.error_source, task))
    return run_episode(env, agent, task, show_progress)

  monkeypatch.setattr(continual.evaluation, "run_episode", counting)
  resumed = False
  with pytest.raises(KeyboardInterrupt):
    continual.run_seed(0, tiny)
  kept = continual.finished_seeds_folder(tiny) / continual.EPISODES_FOLDER
  assert len(list(kept.glob("seed0-*.json"))) == finished_before_interruption
  resumed = True
  scores = continual.run_seed(0, tiny, show_progress=True)
  assert (
    f"resuming seed 0: {finished_before_interruption} of its {total} episodes"
    in capsys.readouterr().err
  )
  assert len(episodes) == total and len(set(episodes)) == total  # None ran twice.
  episode_snapshots.discard_folder(continual.finished_seeds_folder(tiny))
  assert continual.run_seed(0, tiny) == scores  # Uninterrupted: the same scores.
  assert len(episodes) == 2 * total


def test_damaged_saved_exp1s_scores_run_again(two_stages, monkeypatch):
  tiny = profiles.get("tiny")
  expected = continual.run_seed(0, tiny)
  path = continual.finished_seeds_folder(tiny) / "seed0.json"
  path.write_text(path.read_text().replace('"seed": 0', '"seed": 7'))
  with pytest.warns(UserWarning, match="unreadable saved scores"):
    assert continual.run_seed(0, tiny) == expected
  assert json.loads(path.read_text())["scores"] == expected  # Saved again.
  # With the seed's file gone, a damaged episode's file runs that episode alone again.
  path.unlink()
  episode = (
    continual.finished_seeds_folder(tiny)
    / continual.EPISODES_FOLDER
    / ("seed0-configuration2-closed-spiral.json")
  )
  episode.write_text(episode.read_text()[:-5])  # Truncated.
  ran, run_episode = [], continual.evaluation.run_episode
  monkeypatch.setattr(
    continual.evaluation,
    "run_episode",
    lambda *arguments: ran.append(arguments[2]) or run_episode(*arguments),
  )
  with pytest.warns(UserWarning, match="configuration2-closed.*unreadable saved scores"):
    assert continual.run_seed(0, tiny) == expected
  assert ran == ["spiral"]
