"""Runs side by side and cut short, and inputs that are not what they seem: records of the same
second kept apart, one reference computation per data home, an interrupt after the record is
written, special files and links as inputs and outputs, counts too large to hold, names that
would leave their folder, and environment variables that name the wrong thing."""

import contextlib
import os
import pathlib
import re
import select
import signal
import subprocess
import sys
import time

import numpy as np
import process_tree
import pytest

from softbench import cli
from softbench import plots
from softbench import records
from softbench import robots
from softbench import storage
from softbench import terminal
from softbench import tuning
from softbench import zoo
from softbench.episodes import snapshots as episode_snapshots
from softbench.records import provenance
from softbench.runners import continual
from softbench.runners import retrain
from softbench.runners import run
from softbench.runners import run_settings
from softbench.runners import saving
from softbench.suite import references
from softbench.sweep import grid as sweep_grid
from softbench.sweep import guard

COMMITTED_RESULTS = pathlib.Path(__file__).resolve().parents[1] / records.DEFAULT_FOLDER
CHILD_DEADLINE_S = 120  # (s) A child program still running after this has hung.


@pytest.fixture
def committed_record() -> dict:
  """A committed ``softbench run`` record, as read from the repository's results."""
  return records.read(min(COMMITTED_RESULTS.glob("zero-pneumatic-433-circle-default-*.json")))


def test_records_of_the_same_second_are_kept_apart(committed_record, tmp_path, capsys):
  # Two runs that finished in the same second wrote one file name: the second replaced the first.
  first = saving.save(run, committed_record, tmp_path)[0]
  second = saving.save(run, committed_record, tmp_path)[0]
  assert first == run.record_path(committed_record, tmp_path)
  assert second == first.with_name(f"{first.stem}-2.json")
  assert sorted(tmp_path.iterdir()) == sorted([first, second])
  assert records.read(first) == records.read(second) == committed_record
  assert f"result record: {second}" in capsys.readouterr().out


@pytest.mark.parametrize("hard_links", [True, False], ids=["linked", "claimed"])
def test_a_new_file_never_replaces_one(hard_links, tmp_path, monkeypatch):
  if not hard_links:  # A file system without hard links (os.link fails as on FAT).
    monkeypatch.setattr(os, "link", lambda *_: (_ for _ in ()).throw(PermissionError(1, "no")))
  path = tmp_path / "record.json"
  assert storage.write_new(path, "first")
  assert not storage.write_new(path, "second")
  assert path.read_text() == "first" and sorted(tmp_path.iterdir()) == [path]


_REFERENCE_PROGRAM = """
from softbench import robots
from softbench.suite import references
from softbench.sweep import grid as sweep_grid
from softbench.sweep import guard
references._simulate = None  # Simulating it here fails: the waiting process reads it.
print(references.reference(robots.make("tendon-1"), "babbling", 5).poses.shape)
"""


def test_one_reference_computation_per_data_home(tmp_path, monkeypatch):
  # Two runs of one setting both computed its reference.
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path))
  other = None
  simulate = references._simulate

  def simulated_while_another_process_asks(*args):
    nonlocal other
    other = subprocess.Popen(
      [sys.executable, "-c", _REFERENCE_PROGRAM], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    said, _, _ = select.select([other.stderr], [], [], CHILD_DEADLINE_S)
    assert said and b"waiting for another process making the reference" in other.stderr.readline()
    return simulate(*args)

  monkeypatch.setattr(references, "_simulate", simulated_while_another_process_asks)
  try:
    made = references.reference(robots.make("tendon-1"), "babbling", 5)
    out, error = other.communicate(timeout=CHILD_DEADLINE_S)
  finally:
    if other is not None:
      other.kill()  # A no-op once it has ended.
  assert other.returncode == 0, error
  assert out.decode() == f"{made.poses.shape}\n"


def _killed(*_) -> None:
  """``kill`` of this process, as from another terminal; the handler raises at once."""
  os.kill(os.getpid(), signal.SIGTERM)
  time.sleep(CHILD_DEADLINE_S)


def test_an_interrupt_once_the_record_is_written_leaves_a_complete_run(
  tmp_path, monkeypatch, run_wide_home, capsys
):
  # It said "interrupted; run the same command again to resume", and the rerun wrote a second
  # record of the same run.
  run_wide_home("tendon-1")
  monkeypatch.setattr(plots, "save_run_plots", _killed)
  argv = ["run", "--task", "circle", "--agent", "zero", "--robot", "tendon-1", "--profile", "tiny"]
  assert cli.main([*argv, "--seeds", "1", "--results", str(tmp_path)]) == cli.EXIT_INTERRUPTED
  (path,) = tmp_path.glob("*.json")
  lines = [
    line for line in capsys.readouterr().err.splitlines() if not line.startswith("simulating ")
  ]
  assert len(lines) == 1 and lines[0].startswith(
    f"softbench: interrupted once the run was complete: its result record is {path} ("
  )
  assert records.read(path)["seeds"] == 1
  settings = run_settings.settings("circle", "zero", "tendon-1", 1, "tiny")
  assert not episode_snapshots.folder(settings).exists()  # Nothing left to resume from.


def test_an_interrupt_during_a_held_step_waits_for_its_end():
  steps = []
  with terminal.sigterm_as_interrupt(), pytest.raises(KeyboardInterrupt):
    with terminal.interrupts_held():
      os.kill(os.getpid(), signal.SIGTERM)
      time.sleep(0.1)
      steps.append("written")
    steps.append("after")
  assert steps == ["written"]


@contextlib.contextmanager
def _deadline(seconds: int):
  """Within the block, a wait longer than ``seconds`` fails the test instead of hanging it."""

  def expired(*_):
    raise TimeoutError(f"still waiting after {seconds} s")

  previous = signal.signal(signal.SIGALRM, expired)
  signal.alarm(seconds)
  try:
    yield
  finally:
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def test_a_fifo_among_the_records_is_refused_not_waited_on(committed_record, tmp_path, capsys):
  # softbench leaderboard waited forever for a writer.
  records.write(committed_record, tmp_path / "good.json")
  os.mkfifo(tmp_path / "x.json")
  with _deadline(30):
    assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  assert capsys.readouterr().err == (
    f"softbench: error: {tmp_path / 'x.json'}: a FIFO, not a regular file\n"
  )


HUGE = "99999999999999999999"  # A count that filled the memory or hung the command.
TINY_RUN = ["--agent", "zero", "--robot", "tendon-1", "--profile", "tiny"]


@pytest.fixture
def no_work(monkeypatch):
  """Every command's work fails the test: a count must be refused before any starts."""

  def started(*_, **__):
    raise AssertionError("work started")

  for module, name in (
    (run, "execute_episodes"),
    (continual, "execute"),
    (retrain, "execute"),
    (sweep_grid, "existing_record"),  # A sweep's first step once its settings are checked.
    (tuning, "tune"),
  ):
    monkeypatch.setattr(module, name, started)


@pytest.mark.parametrize(
  "argv,message",
  [
    (["run", "--task", "circle", *TINY_RUN, "--seeds", HUGE], "seeds must be at most 1,000"),
    (["run", "--protocol", "exp1s", "--agent", "smpl", "--seeds", HUGE], "seeds must be at most"),
    (
      ["run", "--task", "reach", *TINY_RUN[2:], "--agent", "smpl", "--adaptive", "--targets", HUGE],
      "targets must be at most 10,000",
    ),
    (
      [
        "sweep",
        "--robots",
        "tendon-1",
        "--tasks",
        "circle",
        "--agents",
        "zero",
        "--dry-run",
        "--seeds",
        HUGE,
      ],
      "seeds must be at most",
    ),
    (["retrain", "--robot", "tendon-2", "--fault", "2:0:0", "--seeds", HUGE], "seeds must be at"),
    (["zoo", "add", "--agent", "smpl", "--robot", "tendon-1", "--seeds", HUGE], "seeds must be"),
    (["zoo", "add", "--agent", "smpl", "--robot", "tendon-1", "--seed", HUGE], "seed must be"),
    (["zoo", "remove", "--agent", "smpl", "--robot", "tendon-1", "--seeds", HUGE], "seeds must"),
    (["tune", "--agent", "lstm", "--robot", "tendon-1", "--trials", HUGE], "trials must be at"),
  ],
)
def test_a_count_too_large_is_refused_before_any_work(
  argv, message, no_work, tmp_path, monkeypatch, capsys
):
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  monkeypatch.chdir(tmp_path)
  assert cli.main(argv) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.startswith(f"softbench: error: {message}") and error.count("\n") == 1, error


@pytest.mark.parametrize(
  "shape,data_bytes,message",
  [((10**11, 6), 480, "claims 100,000,000,000 rows"), ((1000, 6), 480, "more than the file's")],
)
def test_an_npy_trajectory_is_refused_from_its_header(
  shape, data_bytes, message, no_work, tmp_path, capsys
):
  # A header claiming shape (1e11, 6) was an _ArrayMemoryError traceback.
  path = tmp_path / "claimed.npy"
  with open(path, "wb") as file:
    header = {"descr": "<f8", "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(file, header)
    file.write(bytes(data_bytes))
  argv = ["run", "--task", "custom", *TINY_RUN, "--trajectory", str(path)]
  assert cli.main([*argv, "--results", str(tmp_path)]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.count("\n") == 1 and "is unreadable: its header" in error and message in error


TINY_TUNE = ["tune", "--agent", "lstm", "--robot", "tendon-1", "--profile", "tiny"]


@pytest.mark.parametrize(
  "study,message",
  [
    ("../../../tmp/x", "must be a plain name"),  # Wrote its summary outside the data home.
    ("sub/study", "must be a plain name"),
    ("..", "must be a plain name"),
    ("two\nlines", "no control characters"),
    ("x" * 201, "at most 200 bytes"),
  ],
)
def test_a_study_name_is_a_plain_name(study, message, no_work, tmp_path, monkeypatch, capsys):
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  assert cli.main([*TINY_TUNE, "--study", study]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.startswith("softbench: error: the study name") and error.count("\n") == 1
  assert message in error


def test_a_summary_that_cannot_be_written_is_refused_before_the_study(
  tmp_path, monkeypatch, capsys
):
  # A folder given as --summary failed only once the study had run.
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  monkeypatch.setattr(tuning.study, "run", lambda *_: pytest.fail("the study ran"))
  assert cli.main([*TINY_TUNE, "--summary", str(tmp_path)]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error == (
    f"softbench: error: cannot write the study summary {str(tmp_path)!r}: it is a folder, not a "
    "regular file\n"
  )


@pytest.mark.parametrize("kind", ["a file", "missing"])
def test_a_zoo_variable_that_names_no_folder_is_refused(
  kind, no_work, tmp_path, monkeypatch, capsys
):
  # The zoo was silently not used: its agents trained again.
  named = tmp_path / "zoo"
  if kind == "a file":
    named.write_text("")
  monkeypatch.setenv(zoo.VARIABLE, str(named))
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  argv = ["run", "--task", "circle", *TINY_RUN, "--results", str(tmp_path / "results")]
  assert cli.main(argv) == cli.EXIT_USAGE
  found = "is a file" if kind == "a file" else "does not exist"
  assert capsys.readouterr().err.startswith(
    f"softbench: error: $SOFTBENCH_ZOO={str(named)!r} {found}, not a zoo folder; "
  )


def test_a_cache_home_that_is_a_file_is_named_as_such(tmp_path, monkeypatch, capsys):
  # It was reported as $SOFTBENCH_HOME, which was not set.
  monkeypatch.delenv(storage.HOME_VARIABLE, raising=False)
  cache = tmp_path / "cache"
  cache.write_text("")
  monkeypatch.setenv("XDG_CACHE_HOME", str(cache))
  assert cli.main(["collect", "--robot", "tendon-1", "--samples", "10"]) == cli.EXIT_USAGE
  assert capsys.readouterr().err == (
    f"softbench: error: cannot write the data home ($XDG_CACHE_HOME/softbench) "
    f"{str(cache / 'softbench')!r}: {str(cache)!r} is not a folder\n"
  )


_GUARDED_PROGRAM = """
import importlib.util, subprocess, sys, time
spec = importlib.util.spec_from_file_location("guard", {guard!r})
guard = importlib.util.module_from_spec(spec)
spec.loader.exec_module(guard)
tree = subprocess.Popen(["sh", "-c", "sleep 600 & sleep 600"])  # As Ray's head and its agents.
time.sleep(0.5)
guard.start({{tree.pid}})
print("guarded", flush=True)
time.sleep(600)
"""


@pytest.mark.skipif(not process_tree.PROC.is_dir(), reason="reads Linux's /proc")
def test_a_local_ray_ends_with_its_driver_killed_outright():
  # After kill -9 of a sweep, Ray's dashboard and runtime-env agents lived 61 s more.
  program = _GUARDED_PROGRAM.format(guard=guard.__file__)
  driver = subprocess.Popen([sys.executable, "-c", program], stdout=subprocess.PIPE, text=True)
  left = set()
  try:
    said, _, _ = select.select([driver.stdout], [], [], CHILD_DEADLINE_S)
    assert said and driver.stdout.readline() == "guarded\n"
    left = process_tree.descendants(driver.pid)
    assert len(left) == 4  # sh, its two sleeps, and the guard.
    driver.kill()
    driver.wait()
    assert not process_tree.still_running(left, 5)
  finally:
    driver.kill()  # A no-op once it has ended.
    process_tree.kill(left)


def test_a_record_s_commit_is_dirty_for_changed_code_not_for_new_records(tmp_path):
  git = lambda *argv: subprocess.run(["git", *argv], cwd=tmp_path, check=True, capture_output=True)
  (tmp_path / "softbench").mkdir()
  (tmp_path / "softbench" / "module.py").write_text("X = 1\n")
  git("init", "-q")
  git("add", ".")
  git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "code")
  clean = provenance.git_commit(tmp_path)
  assert re.fullmatch("[0-9a-f]{40}", clean)
  (tmp_path / "leaderboard" / "results").mkdir(parents=True)
  (tmp_path / "leaderboard" / "results" / "record.json").write_text("{}")
  assert provenance.git_commit(tmp_path) == clean  # A long run's own records.
  (tmp_path / "smpl").mkdir()
  (tmp_path / "smpl" / "new.py").write_text("")
  assert provenance.git_commit(tmp_path) == f"{clean}-dirty"  # Untracked code.
  (tmp_path / "smpl" / "new.py").unlink()
  (tmp_path / "softbench" / "module.py").write_text("X = 2\n")
  assert provenance.git_commit(tmp_path) == f"{clean}-dirty"
