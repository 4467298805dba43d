"""Fixtures shared by the test files."""

import contextlib
import io
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

import example_task
import gymnasium
import pytest
import worker_hooks

from smpl import fitting
from smpl import snapshots
from softbench import data
from softbench import leaderboard
from softbench import profiles
from softbench import storage
from softbench import zoo
from softbench.continual import strategies
from softbench.continual import streams
from softbench.data import dataset as data_files
from softbench.learning import inverse as inverse_training
from softbench.learning import protocols
from softbench.runners import continual
from softbench.suite import registry as task_registry


@pytest.fixture(autouse=True)
def no_repository_zoo(monkeypatch):
  """Tests train what they use: the repository's zoo stays out unless a test names a zoo."""
  monkeypatch.setenv(zoo.VARIABLE, zoo.OFF)


@pytest.fixture
def restored_tasks(monkeypatch):
  """The task registry and Gymnasium's ids as they were, after the test."""
  monkeypatch.setattr(task_registry, "_TASKS", dict(task_registry._TASKS))
  known_ids = set(gymnasium.registry)
  yield
  for added in set(gymnasium.registry) - known_ids:  # The Gymnasium ids of a registered task.
    del gymnasium.registry[added]


@pytest.fixture
def figure_eight(restored_tasks) -> str:
  """The name of tracking task ``figure_eight``, registered from outside softbench for the test
  (``example_task.register_figure_eight``)."""
  return example_task.register_figure_eight()


@pytest.fixture(scope="session")
def run_folder(tmp_path_factory) -> pathlib.Path:
  """A folder that every test process of this pytest run shares (pytest-xdist's workers: their
  common temporary root), for what is worth making once per run rather than once per process."""
  if "PYTEST_XDIST_WORKER" not in os.environ:  # Not distributed: this process's own root.
    return tmp_path_factory.getbasetemp()
  return tmp_path_factory.getbasetemp().parent


@pytest.fixture(scope="session")
def babbled_datasets(run_folder):
  """``of(robot)``: the datasets folder of a data home holding ``robot``'s tiny babbling dataset
  (data seed ``inverse_training.DATA_SEED``), collected once per test run: collecting it took most
  of a tiny training's time. Test processes share that data home as users' processes do (the first
  collects, the others wait for it and read it; their waiting line is not shown)."""
  collected = {}

  def of(robot: str):
    if robot not in collected:
      template = run_folder / f"babbled-{robot}"
      with pytest.MonkeyPatch.context() as patched, contextlib.redirect_stderr(io.StringIO()):
        patched.setenv("SOFTBENCH_HOME", str(template))
        data.collect(
          robot,
          samples=profiles.get("tiny").samples,
          seed=inverse_training.DATA_SEED,
          progress=False,
        )
      collected[robot] = template / data_files.DATASETS_FOLDER
    return collected[robot]

  return of


@pytest.fixture(scope="session")
def with_babbled_dataset(babbled_datasets):
  """``give(home, robot="tendon-2")``: copies ``babbled_datasets(robot)`` into data home ``home``
  (which stays whatever the data home was); ``home``."""

  def give(home, robot="tendon-2"):
    shutil.copytree(babbled_datasets(robot), home / data_files.DATASETS_FOLDER, dirs_exist_ok=True)
    return home

  return give


@pytest.fixture
def babbled_home(monkeypatch, with_babbled_dataset):
  """``into(home, robot="tendon-2")``: makes ``home`` the data home, with a copy of
  ``babbled_datasets``. For tests of what is trained in a home of its own; the dataset's own
  determinism and caching are test_data's subject."""

  def into(home, robot="tendon-2"):
    monkeypatch.setenv("SOFTBENCH_HOME", str(with_babbled_dataset(home, robot)))
    return home

  return into


@pytest.fixture(scope="session")
def run_wide_homes(run_folder, babbled_datasets):
  """``of(robot)``: ``robot``'s run-wide data home, holding its tiny dataset: one home that every
  test process of the run shares, as users' processes may, so that what a test makes there (a
  tiny agent, a reference) is made once per run. Only for tests that read back what they make:
  none damages a file or keeps a run there."""

  def of(robot: str) -> pathlib.Path:
    home = run_folder / f"run-wide-{robot}"
    if not (home / data_files.DATASETS_FOLDER).exists():  # Copied whole, then moved in at once.
      home.mkdir(parents=True, exist_ok=True)
      with tempfile.TemporaryDirectory(dir=home) as incoming:
        shutil.copytree(babbled_datasets(robot), pathlib.Path(incoming) / "datasets")
        with contextlib.suppress(OSError):  # Another process moved its copy in first.
          os.rename(pathlib.Path(incoming) / "datasets", home / data_files.DATASETS_FOLDER)
    return home

  return of


@pytest.fixture
def run_wide_home(monkeypatch, run_wide_homes):
  """``into(robot)``: makes ``run_wide_homes(robot)`` the data home."""

  def into(robot: str):
    monkeypatch.setenv("SOFTBENCH_HOME", str(run_wide_homes(robot)))

  return into


@pytest.fixture
def interrupted_training(monkeypatch):
  """A context manager within which training stops with KeyboardInterrupt in its fourth epoch
  (every agent has run at least one whole fit by then, and one epoch of the fit under way),
  snapshots saved at every epoch."""
  monkeypatch.setattr(snapshots, "SAVE_INTERVAL_S", 0.0)

  @contextlib.contextmanager
  def interrupted():
    epochs, train_epoch = 0, fitting._train_epoch

    def interrupted_in_the_fourth_epoch(*args):
      nonlocal epochs
      epochs += 1
      if epochs == 4:
        raise KeyboardInterrupt
      return train_epoch(*args)

    with monkeypatch.context() as patched:
      patched.setattr(fitting, "_train_epoch", interrupted_in_the_fourth_epoch)
      with pytest.raises(KeyboardInterrupt):
        yield

  return interrupted


@pytest.fixture
def registries(monkeypatch):
  """The continual stream and strategy registries as they are, restored after the test."""
  monkeypatch.setattr(streams, "_STREAMS", dict(streams._STREAMS))
  monkeypatch.setattr(streams, "STREAMS", streams.STREAMS)
  monkeypatch.setattr(strategies, "_STRATEGIES", dict(strategies._STRATEGIES))
  monkeypatch.setattr(strategies, "STRATEGIES", strategies.STRATEGIES)


@pytest.fixture
def two_stages(monkeypatch, tmp_path, babbled_home):
  """Exp1S on tendon-1 then tendon-2 instead of tendon-1 .. 5, in a fresh data home that holds
  their tiny babbling datasets (``babbled_home``); the stages."""
  for robot in worker_hooks.EXP1S_STAGES:
    babbled_home(tmp_path / "home", robot)
  monkeypatch.setitem(protocols.PROTOCOLS, continual.PROTOCOL, worker_hooks.shortened_exp1s())
  return worker_hooks.EXP1S_STAGES


@pytest.fixture
def assert_regenerates_identically():
  """Checks that the pages of a results folder come out byte-identical when written again and
  when the folder (its records written in another order) is moved elsewhere."""

  def check(results, tmp_path):
    first = leaderboard.write(leaderboard.build(results), results, tmp_path / "site")
    contents = [path.read_bytes() for path in first]
    leaderboard.write(leaderboard.build(results), results, tmp_path / "site")
    assert [path.read_bytes() for path in first] == contents
    moved = tmp_path / "elsewhere"
    (moved / "results").mkdir(parents=True)
    for path in sorted(results.glob("*.json"), reverse=True):
      (moved / "results" / path.name).write_bytes(path.read_bytes())
    again = leaderboard.write(
      leaderboard.build(moved / "results"), moved / "results", moved / "site"
    )
    assert [path.read_bytes() for path in again] == contents

  return check


@pytest.fixture
def assert_one_line_retraining():
  """Checks that caught warnings hold one ``storage.CorruptFileWarning``: one line naming the
  damaged file and saying that it is trained again."""

  def check(caught, path):
    corrupt = storage.CorruptFileWarning
    (warning,) = [entry for entry in caught if issubclass(entry.category, corrupt)]
    message = str(warning.message)
    assert str(path) in message and "training it again" in message and "\n" not in message

  return check


@pytest.fixture
def broken_egl_environment():
  """Environment variables under which EGL's library loads but no display opens: glvnd finds no
  EGL driver without its vendor files."""
  return {"__EGL_VENDOR_LIBRARY_FILENAMES": "/nonexistent/egl_vendor.json"}


@pytest.fixture
def launch_with_broken_egl(broken_egl_environment):
  """Runs ``softbench ARGV`` in a child with MUJOCO_GL unset and an EGL that cannot open."""

  def launch(argv: list[str]) -> subprocess.CompletedProcess:
    inherited = {
      name: value
      for name, value in os.environ.items()
      if name not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")
    }
    return subprocess.run(
      [sys.executable, "-m", "softbench.launcher", *argv],
      env={**inherited, **broken_egl_environment},
      capture_output=True,
      text=True,
      timeout=300,
    )

  return launch
