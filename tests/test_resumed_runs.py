"""An interrupted ``softbench run`` resumes: finished seeds are kept and not run again, with the
same record as an uninterrupted run; a damaged saved seed runs again; an unfinished episode of an
agent that can resume one goes on from where it stopped, to the same episode."""

import dataclasses

import numpy as np
import pytest

from softbench import cli
from softbench import episodes
from softbench import records
from softbench import robots
from softbench import suite
from softbench.agents import reference
from softbench.episodes import snapshots as episode_snapshots
from softbench.runners import evaluation
from softbench.runners import run
from softbench.runners import run_settings

SEEDS = 3


@pytest.fixture(autouse=True)
def data_home(tmp_path, monkeypatch):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))


def tiny_run(agent: str = "random") -> run_settings.RunSettings:
  return run_settings.settings("circle", agent, "tendon-1", seeds=SEEDS, profile="tiny")


def interrupted_at(seed: int, monkeypatch) -> list[int]:
  """Runs tiny_run() until ``seed`` starts (raising KeyboardInterrupt there); the seeds run."""
  started, episode_and_arm = [], run._episode_and_arm

  def stop_at_seed(settings, index, *options):
    started.append(index)
    if index == seed:
      raise KeyboardInterrupt
    return episode_and_arm(settings, index, *options)

  with monkeypatch.context() as patch:
    patch.setattr(run, "_episode_and_arm", stop_at_seed)
    with pytest.raises(KeyboardInterrupt):
      run.execute(tiny_run(), show_progress=False, workers=1)
  return started


def seeds_run(monkeypatch) -> tuple[dict, list[int]]:
  """A full run of tiny_run(): its record and the seeds it ran (rather than reloaded)."""
  started, episode_and_arm = [], run._episode_and_arm

  def counting(settings, index, *options):
    started.append(index)
    return episode_and_arm(settings, index, *options)

  with monkeypatch.context() as patch:
    patch.setattr(run, "_episode_and_arm", counting)
    record = run.execute(tiny_run(), show_progress=False, workers=1)
  return record, started


def test_an_interrupted_run_resumes_from_its_finished_seeds(monkeypatch):
  assert interrupted_at(2, monkeypatch) == [0, 1, 2]
  resumed, started = seeds_run(monkeypatch)
  assert started == [2]
  assert not episode_snapshots.folder(tiny_run()).exists()
  fresh, started = seeds_run(monkeypatch)  # Finished: a new run evaluates afresh ...
  assert started == [0, 1, 2]
  assert resumed["per_seed"] == fresh["per_seed"]  # ... to the same scores.


def test_a_damaged_saved_seed_runs_again(monkeypatch):
  interrupted_at(1, monkeypatch)
  saved = episode_snapshots.folder(tiny_run()) / "seed0.npz"
  saved.write_bytes(saved.read_bytes()[:-100])
  with pytest.warns(UserWarning, match="unreadable saved episode"):
    _, started = seeds_run(monkeypatch)
  assert started == [0, 1, 2]


def test_a_saved_seed_of_another_seed_or_run_is_refused(monkeypatch, tmp_path):
  interrupted_at(1, monkeypatch)  # Seed 0 finished.
  folder = episode_snapshots.folder(tiny_run())
  (folder / "seed1.npz").write_bytes((folder / "seed0.npz").read_bytes())  # Intact, misplaced.
  other = episode_snapshots.folder(tiny_run("zero"))
  other.mkdir(parents=True)
  (other / "seed0.npz").write_bytes((folder / "seed0.npz").read_bytes())
  with pytest.warns(UserWarning, match="seed1.npz: unreadable saved episode .*not for this run"):
    _, started = seeds_run(monkeypatch)
  assert started == [1, 2]
  with pytest.warns(UserWarning, match="seed0.npz: unreadable saved episode .*not for this run"):
    episode_snapshots.load(tiny_run("zero"), 0)


def test_a_failed_save_warns_and_the_run_goes_on(monkeypatch):
  expected, _ = seeds_run(monkeypatch)

  def disk_full(path, content):
    raise OSError(28, "No space left on device")

  monkeypatch.setattr(episode_snapshots.storage, "write_atomically", disk_full)
  with pytest.warns(UserWarning, match="No space left on device.*the run goes on"):
    record, started = seeds_run(monkeypatch)
  assert started == [0, 1, 2]
  assert record["per_seed"] == expected["per_seed"]


def test_other_settings_never_reuse_saved_seeds(monkeypatch):
  folders = {
    episode_snapshots.folder(settings)
    for settings in (
      tiny_run(),
      tiny_run("zero"),
      run_settings.settings(
        "circle", "random", "tendon-1", seeds=SEEDS, profile="tiny", eval_mode="open-loop"
      ),
      run_settings.settings("circle", "random", "tendon-2", seeds=SEEDS, profile="tiny"),
    )
  }
  assert len(folders) == 4
  monkeypatch.setattr(episode_snapshots, "_device", lambda: "cuda")  # Another device.
  assert episode_snapshots.folder(tiny_run()) not in folders


def test_an_edited_trajectory_file_never_reuses_saved_seeds(tmp_path):
  path = tmp_path / "path.csv"
  path.write_text("0.0,0.0,-0.05\n")
  custom = dataclasses.replace(tiny_run(), task="custom", trajectory=str(path))
  before = episode_snapshots.folder(custom)
  path.write_text("0.0,0.01,-0.05\n")
  assert episode_snapshots.folder(custom) != before


def test_a_failed_record_write_keeps_the_seeds_for_the_next_run(monkeypatch, tmp_path, capsys):
  argv = [
    "run",
    "--task",
    "circle",
    "--agent",
    "random",
    "--robot",
    "tendon-1",
    "--seeds",
    str(SEEDS),
    "--profile",
    "tiny",
    "--workers",
    "1",  # In this process: starting worker processes took most of the test's time.
    "--results",
    str(tmp_path / "records"),
  ]

  def disk_full(record, path):
    raise OSError(28, "No space left on device", str(path))

  with monkeypatch.context() as patch:
    patch.setattr(records, "write_new", disk_full)
    assert cli.main(argv) == cli.EXIT_FAILURE
  assert "No space left on device" in capsys.readouterr().err.strip().splitlines()[-1]
  assert len(list(episode_snapshots.folder(tiny_run()).glob("seed*.npz"))) == SEEDS
  assert cli.main(argv) == 0
  assert f"resuming: {SEEDS} of {SEEDS} seeds finished" in capsys.readouterr().err
  assert len(list((tmp_path / "records").glob("*.json"))) == 1
  assert not episode_snapshots.folder(tiny_run()).exists()


def _interrupting(monkeypatch, at: list[int]) -> list:
  """Patches the reference agent to count its steps (``act``) and raise KeyboardInterrupt at the
  step numbered in ``at`` (from 1; none if empty); the steps taken, as a list."""
  calls, act = [], reference.ReferenceAgent.act

  def acting(agent, observation):
    calls.append(observation)
    if len(calls) in at:
      raise KeyboardInterrupt
    return act(agent, observation)

  monkeypatch.setattr(reference.ReferenceAgent, "act", acting)
  return calls


def test_an_interrupted_episode_goes_on_mid_way_to_the_same_episode(monkeypatch, tmp_path):
  # The reference agent takes seconds a step on babbling; its episodes resume where they stopped,
  # its memory of simulated actions restored (on tendon-2's babbling, step 5 differs without).
  arm, steps, unfinished = robots.make("tendon-2"), 8, tmp_path / "unfinished.npz"
  monkeypatch.setattr(evaluation, "KEEP_INTERVAL_S", 0.0)  # Kept after every step.

  def episode() -> episodes.Episode:
    env = suite.load(arm, "babbling", seed=0, **suite.length_options("babbling", steps))
    return evaluation.run_episode(
      env, reference.ReferenceAgent(arm, 0), "babbling", False, unfinished
    )

  expected = episode()
  assert not unfinished.exists()  # Removed once the episode ends.
  interrupt_at = [5]
  calls = _interrupting(monkeypatch, interrupt_at)
  with pytest.raises(KeyboardInterrupt):
    episode()
  assert unfinished.exists()
  calls.clear()
  interrupt_at.clear()
  resumed = episode()
  assert len(calls) == steps - 4  # The agent acts only after the replay of the 4 steps kept.
  for name in ("targets", "achieved", "poses", "actions", "rewards"):
    np.testing.assert_array_equal(getattr(resumed, name), getattr(expected, name))
  assert not unfinished.exists()


def test_a_damaged_unfinished_episode_starts_again(monkeypatch):
  settings = run_settings.settings("babbling", "reference", "tendon-1", seeds=1, profile="tiny")
  monkeypatch.setattr(evaluation, "KEEP_INTERVAL_S", 0.0)
  expected = run.fresh_seed(settings, 0)[1]
  interrupt_at = [3]
  calls = _interrupting(monkeypatch, interrupt_at)
  with pytest.raises(KeyboardInterrupt):
    run.fresh_seed(settings, 0)
  unfinished = episode_snapshots.partial_path(settings, 0)
  unfinished.write_bytes(unfinished.read_bytes()[:-50])
  calls.clear()
  interrupt_at.clear()
  with pytest.warns(UserWarning, match="unreadable unfinished episode.*the episode starts again"):
    again = run.fresh_seed(settings, 0)[1]
  assert len(calls) == len(expected.actions)
  np.testing.assert_array_equal(again.actions, expected.actions)
