"""Every registered agent on a small task set with the tiny profile, and ``softbench run``."""

import json
import os
import pathlib
import shutil
import stat
import warnings

from dm_control.rl import control
import numpy as np
import pytest
import torch

from softbench import agents
from softbench import cli
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import storage
from softbench import suite
from softbench import terminal
from softbench.agents import learned
from softbench.learning import checkpoints
from softbench.learning import forward_models
from softbench.learning import protocols
from softbench.records import fields
from softbench.runners import evaluation
from softbench.runners import parallel_seeds
from softbench.runners import run
from softbench.runners import run_settings

# Every task of the suite on tendon-2, and one on the pneumatic arm.
TASKS = tuple(pair for pair in suite.ALL_TASKS if pair[0] == "tendon-2") + (
  ("pneumatic-433", "spiral"),
)
EPISODE_STEPS = 2  # Control steps of each test episode (the second acts on a measured error).
LEARNED_AGENTS = [name for name in agents.AGENTS if agents.describe(name).learned]


@pytest.fixture(autouse=True)
def shared_home(tmp_path_factory, babbled_home):
  """One data home for the file, holding tendon-2's tiny dataset: checkpoints are made once, then
  reused."""
  babbled_home(tmp_path_factory.getbasetemp() / "agents_home")


def episode(agent_name, robot, task, seed=0):
  agent = agents.make(agent_name, robot, seed, "tiny")
  env = suite.load(robot, task, seed=seed, **suite.length_options(task, EPISODE_STEPS))
  return evaluation.run_episode(env, agent, task)


@pytest.mark.parametrize("robot,task", TASKS)
@pytest.mark.parametrize("agent_name", agents.AGENTS)
class TestEveryAgent:
  @pytest.fixture(autouse=True)
  def trained_once_per_run(self, robot, run_wide_home):
    run_wide_home(robot)

  def test_actions_are_finite_in_bounds_and_the_same_for_a_seed(self, agent_name, robot, task):
    # A learned agent is made again from its cached checkpoint the second time; training itself
    # is checked by test_training_is_deterministic_and_its_checkpoint_round_trips.
    first, second = episode(agent_name, robot, task), episode(agent_name, robot, task)
    assert first.actions.shape == (EPISODE_STEPS, robots.make(robot).action_dim)
    assert np.all(np.isfinite(first.actions)) and np.all(np.abs(first.actions) <= 1.0)
    np.testing.assert_array_equal(first.actions, second.actions)


@pytest.mark.parametrize("agent_name", LEARNED_AGENTS)
def test_training_is_deterministic_and_its_checkpoint_round_trips(
  agent_name, tmp_path, babbled_home, run_wide_home, assert_one_line_retraining
):
  """Trained in a data home that holds only the babbling dataset (copied: its collection's
  determinism is test_data's), then made again from its checkpoint: the same actions. A damaged
  checkpoint, its forward models gone too, is reported in one line and trained again from
  scratch, to the same actions. Another seed (the run-wide home's seed 0) acts otherwise."""
  babbled_home(tmp_path)
  trained = episode(agent_name, "tendon-2", "circle", 1)  # Trains, then saves the checkpoint.
  (checkpoint,) = (tmp_path / checkpoints.CHECKPOINT_FOLDER).glob(f"{agent_name}-*.pt")
  loaded = episode(agent_name, "tendon-2", "circle", 1)
  np.testing.assert_array_equal(trained.actions, loaded.actions)
  checkpoint.write_bytes(checkpoint.read_bytes()[:1000])
  if (tmp_path / forward_models.FOLDER).exists():  # sac learns without forward models.
    shutil.rmtree(tmp_path / forward_models.FOLDER)
  with pytest.warns(storage.CorruptFileWarning) as caught:
    retrained = episode(agent_name, "tendon-2", "circle", 1)
  assert_one_line_retraining(caught, checkpoint)
  np.testing.assert_array_equal(retrained.actions, trained.actions)
  with warnings.catch_warnings():
    warnings.simplefilter("error")  # Written again whole: it loads without a warning.
    np.testing.assert_array_equal(
      episode(agent_name, "tendon-2", "circle", 1).actions, trained.actions
    )
  assert [path.name for path in checkpoint.parent.iterdir()] == [checkpoint.name]
  run_wide_home("tendon-2")  # Its agents are trained once per run (TestEveryAgent's).
  assert not np.array_equal(episode(agent_name, "tendon-2", "circle", 0).actions, trained.actions)


@pytest.mark.parametrize("damage", ["hello", "flipped weight"])
def test_a_damaged_cached_forward_model_is_trained_again(
  damage, tmp_path, babbled_home, assert_one_line_retraining
):
  babbled_home(tmp_path)
  agents.make("mlp", "tendon-2", 0, "tiny")
  (forward,) = (tmp_path / forward_models.FOLDER).glob("*.pt")
  (checkpoint,) = (tmp_path / checkpoints.CHECKPOINT_FOLDER).glob("mlp-*.pt")
  written = torch.load(checkpoint, weights_only=True)["state_dict"]
  checkpoint.unlink()  # The agent trains again, from the cached forward model.
  content = bytearray(forward.read_bytes())
  if damage == "hello":
    content = bytearray(b"hello")
  else:  # One bit of the largest weight tensor: only the content hash notices.
    state = torch.load(forward, weights_only=True)["state_dict"]
    values = state[max(state, key=lambda name: state[name].numel())].numpy().tobytes()
    content[bytes(content).index(values) + 2] ^= 0x01
  forward.write_bytes(bytes(content))
  with pytest.warns(storage.CorruptFileWarning) as caught:
    agents.make("mlp", "tendon-2", 0, "tiny")
  assert_one_line_retraining(caught, forward)
  again = torch.load(checkpoint, weights_only=True)["state_dict"]
  assert again.keys() == written.keys()
  assert all(torch.equal(again[name], written[name]) for name in again)
  with warnings.catch_warnings():
    warnings.simplefilter("error")
    agents.make("mlp", "tendon-2", 0, "tiny")


def test_a_folder_at_a_checkpoint_path_is_damage_reported_and_replaced(
  tmp_path, babbled_home, assert_one_line_retraining
):
  # The cache owns its paths: whatever stands where its file belongs is damage (one rule,
  # storage.read_cached), reported in one line and replaced by the trained checkpoint.
  babbled_home(tmp_path)
  path = learned.checkpoint_path("mlp", robots.make("tendon-2"), 0, profiles.get("tiny"), False)
  (path / "stray.txt").parent.mkdir(parents=True)
  (path / "stray.txt").write_text("not a checkpoint")
  with pytest.warns(storage.CorruptFileWarning) as caught:
    agents.make("mlp", "tendon-2", 0, "tiny")
  assert_one_line_retraining(caught, path)
  assert path.is_file()


@pytest.mark.parametrize("agent_name", agents.babbling_learners())  # sac: in test_sac.
def test_interrupted_training_resumes_to_the_same_checkpoint(
  agent_name, interrupted_training, tmp_path, babbled_home, run_wide_home
):
  """Trained from scratch, interrupted, then resumed: the checkpoint of the run-wide home's
  uninterrupted training, bit for bit (its name is the same: paths are not part of the key)."""
  babbled_home(tmp_path)
  with interrupted_training():
    agents.make(agent_name, "tendon-2", 0, "tiny")
  # The fit under way kept a snapshot: an inverse model's in the checkpoint's folder, or (SMPL,
  # with a forward model per module) a forward model's in its cache file's folder.
  assert list(tmp_path.rglob("*.partial/fit-1.pt"))
  agents.make(agent_name, "tendon-2", 0, "tiny")
  (checkpoint,) = (tmp_path / checkpoints.CHECKPOINT_FOLDER).glob(f"{agent_name}-*.pt")
  resumed = torch.load(checkpoint, weights_only=False)["state_dict"]
  assert not list(tmp_path.rglob("*.partial"))
  run_wide_home("tendon-2")  # Its agents are trained once per run.
  agents.make(agent_name, "tendon-2", 0, "tiny")
  uninterrupted = torch.load(
    storage.softbench_home() / checkpoints.CHECKPOINT_FOLDER / checkpoint.name, weights_only=False
  )["state_dict"]
  assert resumed.keys() == uninterrupted.keys()
  assert all(torch.equal(resumed[key], uninterrupted[key]) for key in resumed)


def test_agents_reading_the_same_view_share_one_forward_model(tmp_path, monkeypatch, babbled_home):
  trained_views, prepare_column = [], protocols.prepare_column

  def counted(robot, view, *args):
    trained_views.append(view.name)
    return prepare_column(robot, view, *args)

  monkeypatch.setattr(protocols, "prepare_column", counted)

  def lstm_weights(home, agent_names):
    babbled_home(home)
    for name in agent_names:
      agents.make(name, "tendon-2", 0, "tiny")
    (path,) = (home / checkpoints.CHECKPOINT_FOLDER).glob("lstm-*.pt")
    return torch.load(path, weights_only=False)["state_dict"]

  alone = lstm_weights(tmp_path / "alone", ["lstm"])
  assert trained_views == ["whole-arm"]
  shared = lstm_weights(tmp_path / "shared", ["mlp", "lstm"])
  assert trained_views == ["whole-arm", "whole-arm"]  # The MLP trained it; the LSTM found it.
  assert alone.keys() == shared.keys()
  assert all(torch.equal(alone[key], shared[key]) for key in alone)  # As if trained itself.


def test_a_checkpoints_further_arrays_may_not_use_a_parts_name(tmp_path):
  # They would be read back as that part's normalisation.
  clashing = checkpoints.TrainedModels(None, [], [], {"module-1/mean": np.zeros(3)})
  with pytest.raises(ValueError, match="clash"):
    checkpoints.load_or_train(tmp_path / "agent.pt", None, ["module-1"], None, lambda: clashing)
  assert not (tmp_path / "agent.pt").exists()


@pytest.mark.parametrize("mode", fields.ERROR_SOURCES)
def test_error_sources_differ_after_the_first_step(mode):
  agent = agents.make("smpl", "tendon-2", 0, "tiny", acting=learned.Acting(mode))
  env = suite.load("tendon-2", "circle", seed=0, length=4)
  actions = evaluation.run_episode(env, agent, "circle").actions
  open_loop = evaluation.run_episode(env, agent.with_acting(error_source="open-loop"), "circle")
  open_loop = open_loop.actions
  np.testing.assert_array_equal(actions[0], open_loop[0])  # e_0 = 0 in every mode.
  assert np.array_equal(actions, open_loop) == (mode == "open-loop")
  # A run scores an agent only as it asks it to act: one built to act otherwise is refused.
  asked = run_settings.settings("circle", "smpl", "tendon-2", 1, "tiny", eval_mode="open-loop")
  if mode != "open-loop":
    with pytest.raises(ValueError, match=r"^this agent acts as .*, but the run asks for"):
      run.episode_on(agent, agent.robot, asked, 0)


def test_softbench_run_end_to_end(tmp_path, capsys):
  results = tmp_path / "results"
  extra = tmp_path / "record.json"
  argv = [
    "run",
    "--task",
    "circle",
    "--agent",
    "smpl",
    "--robot",
    "tendon-2",
    "--profile",
    "tiny",
    "--results",
    str(results),
    "--json",
    str(extra),
  ]
  assert cli.main(argv) == 0
  out = capsys.readouterr().out
  assert "smpl on circle (tendon-2), profile tiny, eval physics, 2 seed(s)" in out
  for row in ("module 1", "module 2", "mean", "wall time"):
    assert row in out
  (path,) = results.glob("*.json")
  record = json.loads(path.read_text())
  assert record == json.loads(extra.read_text())
  assert (
    record["agent"],
    record["robot"],
    record["task"],
    record["profile"],
    record["eval_mode"],
    record["seeds"],
  ) == ("smpl", "tendon-2", "circle", "tiny", "physics", 2)
  assert [entry["seed"] for entry in record["per_seed"]] == [0, 1]
  assert all(len(entry["position_mm"]["per_module"]) == 2 for entry in record["per_seed"])
  for field in ("softbench_version", "git_commit", "date", "machine", "wall_time_s"):
    assert field in record
  assert record["machine"]["processor"].strip()
  per_module, mean = run.summary(record, "position_mm")
  mean_row = next(line for line in out.splitlines() if line.startswith("mean "))
  assert f"{mean.mean:.2f}" in mean_row


def test_the_worker_count_changes_no_result(tmp_path, monkeypatch):
  asked = []

  def over_seeds(*args):
    asked.append(args[-1])  # The worker count.
    return over_all_seeds(*args)

  over_all_seeds = parallel_seeds.over_seeds
  monkeypatch.setattr(parallel_seeds, "over_seeds", over_seeds)
  records = []
  for workers in ("1", "3"):  # 3 workers for 2 seeds: 2 processes.
    path = tmp_path / f"workers{workers}.json"
    argv = [
      "run",
      "--task",
      "circle",
      "--agent",
      "random",
      "--robot",
      "tendon-1",
      "--profile",
      "tiny",
      "--workers",
      workers,
      "--results",
      str(tmp_path / workers),
      "--json",
      str(path),
    ]
    assert cli.main(argv) == 0
    records.append(json.loads(path.read_text()))
  assert asked == [1, 3]
  assert [entry["seed"] for entry in records[0]["per_seed"]] == [0, 1]
  assert records[0]["per_seed"] == records[1]["per_seed"]
  assert records[0]["per_seed"][0] != records[0]["per_seed"][1]


@pytest.mark.parametrize(
  "argv,message",
  [
    (["--task", "juggle", "--agent", "smpl"], "unknown task"),
    (["--task", "circle", "--agent", "oracle"], "unknown agent"),
    (["--task", "circle", "--agent", "zero", "--robot", "tendon-0"], "1 to 10 modules"),
    (["--task", "circle", "--agent", "zero", "--seeds", "0"], "seeds must be"),
    (["--task", "circle", "--agent", "zero", "--workers", "0"], "workers must be"),
    (["--protocol", "exp1s", "--agent", "smpl", "--workers", "-1"], "workers must be"),
    (["--task", "circle", "--agent", "zero", "--profile", "huge"], "unknown profile"),
    (["--task", "circle", "--agent", "zero", "--eval", "dream"], "unknown eval mode"),
    (["--task", "custom", "--agent", "zero"], "--trajectory"),
    (
      [
        "--task",
        "custom",
        "--agent",
        "zero",
        "--profile",
        "tiny",
        "--trajectory",
        "/nonexistent.npy",
      ],
      "does not exist",
    ),
  ],
)
def test_run_refuses_bad_input_with_one_line(argv, message, capsys, tmp_path):
  assert cli.main(["run", *argv, "--results", str(tmp_path)]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0]
  assert not list(pathlib.Path(tmp_path).glob("*.json"))


def _bad_trajectories(folder: pathlib.Path) -> dict[str, tuple[str, str]]:
  """Trajectory files a user may give, each with the message it gets."""
  (folder / "wrong-shape.csv").write_text("0.0,0.1,0.2\n")
  (folder / "empty.csv").write_text("")
  np.save(folder / "complex.npy", np.ones((3, 12), dtype=complex))
  (folder / "a-folder.csv").mkdir()
  os.mkfifo(folder / "a-fifo.npy")  # Was reported as missing.
  # Finite but absurd: positions of 1e300 m once ran every episode, printed inf ± nan and failed
  # writing the record, leaving saved seeds that failed the same way on every rerun.
  pose = np.array([0.0, 0.0, -0.05, 0.0, 0.0, -1.0])
  np.savetxt(
    folder / "far.csv",
    np.tile(np.concatenate([pose, pose * [1, 1, 1e302, 1, 1, 1]]), (3, 1)),
    delimiter=",",
  )
  long_axis = np.concatenate([pose, pose * [1, 1, 1, 1, 1, 1e300]])
  np.savetxt(folder / "long-axis.csv", np.tile(long_axis, (3, 1)), delimiter=",")
  return {
    "missing": ("nowhere.csv", "does not exist"),
    "far": ("far.csv", "arm lengths) from the base of tendon-2"),
    "long axis": ("long-axis.csv", "unit length"),
    "wrong shape": ("wrong-shape.csv", "must have shape (steps, 12)"),
    "empty": ("empty.csv", "trajectory"),
    "complex": ("complex.npy", "real numbers"),
    "folder": ("a-folder.csv", "is a folder"),
    "fifo": ("a-fifo.npy", "is a FIFO, not a regular file"),
  }


@pytest.mark.parametrize(
  "case", ["missing", "wrong shape", "empty", "complex", "folder", "fifo", "far", "long axis"]
)
def test_a_bad_trajectory_is_refused_before_any_collection_or_training(
  case, capsys, tmp_path, monkeypatch
):
  home = tmp_path / "home"
  monkeypatch.setenv("SOFTBENCH_HOME", str(home))
  name, message = _bad_trajectories(tmp_path)[case]
  argv = [
    "run",
    "--task",
    "custom",
    "--agent",
    "lstm",
    "--robot",
    "tendon-2",
    "--profile",
    "tiny",
    "--trajectory",
    str(tmp_path / name),
    "--results",
    str(tmp_path),
  ]
  assert cli.main(argv) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0], lines
  assert not home.exists()  # No dataset, no checkpoint, no reference.


@pytest.mark.parametrize(
  "flags",
  [
    ["--width", "320"],
    ["--camera", "top"],
    ["--fps", "-1"],
    ["--frames-per-step", "2", "--height", "240"],
  ],
)
@pytest.mark.parametrize(
  "command", [["--task", "circle", "--agent", "zero"], ["--protocol", "exp1s", "--agent", "smpl"]]
)
def test_video_flags_without_a_video_are_refused(command, flags, capsys, tmp_path, monkeypatch):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path / "home"))
  assert cli.main(["run", *command, *flags, "--results", str(tmp_path)]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  verb = "go" if sum(flag.startswith("--") for flag in flags) > 1 else "goes"
  assert len(lines) == 1 and f"{verb} with --video" in lines[0] and flags[0] in lines[0]
  assert not (tmp_path / "home").exists()


@pytest.mark.parametrize(
  "outputs,message",
  [
    (["--results", "a-file"], "it is a file"),
    (["--results", "a-file/records"], "is not a folder"),
    (["--json", "a-folder"], "it is a folder"),
    (["--json", "a-file/record.json"], "is not a folder"),
    # A FIFO, a device and a link were replaced by a regular file.
    (["--json", "a-fifo"], "it is a FIFO, not a regular file"),
    (["--json", "a-device"], "it is a character device, not a regular file"),
    (["--json", "a-link"], "it is a symbolic link, not a regular file"),
    (["--results", "a-fifo"], "it is a FIFO, not a folder"),
  ],
)
@pytest.mark.parametrize(
  "command",
  [
    ["run", "--task", "circle", "--agent", "lstm"],
    ["run", "--protocol", "exp1s", "--agent", "smpl"],
    ["retrain", "--fault", "2:0:0"],
  ],
)
def test_outputs_that_cannot_be_written_are_refused_before_the_run(
  command, outputs, message, capsys, tmp_path, monkeypatch
):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path / "home"))
  monkeypatch.chdir(tmp_path)
  (tmp_path / "a-file").write_text("")
  (tmp_path / "a-folder").mkdir()
  os.mkfifo(tmp_path / "a-fifo")
  (tmp_path / "a-link").symlink_to(tmp_path / "a-file")
  if "a-device" in outputs:  # A device of its own: a broken check must not replace /dev/null.
    try:
      os.mknod(tmp_path / "a-device", stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
      pytest.skip("making a device takes root")
  assert cli.main([*command, "--profile", "tiny", *outputs]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0], lines
  assert not (tmp_path / "home").exists()
  assert stat.S_ISFIFO(os.lstat(tmp_path / "a-fifo").st_mode) and (tmp_path / "a-link").is_symlink()


def test_a_data_home_that_cannot_be_used_is_one_line(capsys, tmp_path, monkeypatch):
  (tmp_path / "a-file").write_text("")
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path / "a-file"))
  argv = ["collect", "--robot", "tendon-1", "--samples", "5", "--workers", "1"]
  assert cli.main(argv) == cli.EXIT_USAGE  # Checked before any work.
  err = capsys.readouterr().err
  error_lines = [line for line in err.splitlines() if "error" in line.lower()]
  assert "Traceback" not in err and len(error_lines) == 1, err
  assert "a-file" in error_lines[0] and "it is a file" in error_lines[0]


@pytest.mark.parametrize(
  "argv",
  [
    ["run", "--task", "circle", "--agent", "zero", "--seeds", "x"],
    ["run", "--task"],
    ["frobnicate"],
    [],
    ["models"],
  ],
)
def test_a_malformed_command_line_is_one_line_and_exit_2(argv, capsys):
  assert cli.main(argv) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  lines = captured.err.strip().splitlines()
  assert len(lines) == 1 and "error:" in lines[0] and "--help)" in lines[0]
  assert not captured.out


def test_help_still_prints_the_usage(capsys):
  assert cli.main(["run", "--help"]) == 0
  assert capsys.readouterr().out.startswith("usage: softbench run")


def test_warnings_print_on_one_line(monkeypatch):
  monkeypatch.setattr(warnings, "formatwarning", warnings.formatwarning)  # Restored afterwards.
  terminal.one_line_warnings()
  assert (
    warnings.formatwarning(
      "snapshot unreadable", RuntimeWarning, "training.py", 215, "saved = load()"
    )
    == "softbench: warning: snapshot unreadable\n"
  )


def test_cli_lists_agents(capsys):
  assert cli.main(["agents"]) == 0
  out = capsys.readouterr().out
  assert all(f"\n{name} " in out for name in agents.AGENTS)


def test_an_unstable_simulation_is_one_line(capsys, tmp_path, monkeypatch):
  def blows_up(*args, **kwargs):
    raise control.PhysicsError("Physics state is invalid. Warning(s) raised: mjWARN_BADQACC")

  monkeypatch.setattr(evaluation, "run_episode", blows_up)
  argv = [
    "run",
    "--task",
    "circle",
    "--agent",
    "zero",
    "--robot",
    "tendon-1",
    "--seeds",
    "1",
    "--profile",
    "tiny",
    "--results",
    str(tmp_path),
  ]
  assert cli.main(argv) == cli.EXIT_FAILURE
  err = capsys.readouterr().err
  assert "Traceback" not in err
  assert err.strip().splitlines()[-1] == (
    "softbench: error: the simulation became unstable "
    "(Physics state is invalid. Warning(s) raised: "
    "mjWARN_BADQACC)"
  )


def test_a_run_writes_its_record_to_the_data_home_not_the_checkout(tmp_path, monkeypatch, capsys):
  # make run, then make test: what a user's run writes must not change the committed records.
  checkout_results = tmp_path / "checkout" / records.DEFAULT_FOLDER
  checkout_results.mkdir(parents=True)
  monkeypatch.chdir(tmp_path / "checkout")
  argv = ["run", "--task", "circle", "--agent", "zero", "--robot", "tendon-1", "--seeds", "1"]
  assert cli.main([*argv, "--profile", "tiny", "--workers", "1"]) == 0
  assert list(checkout_results.iterdir()) == []
  written = list(records.user_folder().glob("*.json"))
  assert len(written) == 1 and written[0].parent == storage.softbench_home() / "results"
  out = capsys.readouterr().out
  assert f"result record: {written[0]}" in out
  assert f"rank your runs: softbench leaderboard --results {records.user_folder()}" in out
