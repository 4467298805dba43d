"""``softbench sweep`` on a Ray cluster of two nodes on this machine (a head and one more, one core
each): its records equal ``softbench run``'s (Exp1S's too), a worker killed mid-task is retried
to the same records, settings with a record are skipped, an interrupted sweep resumes; bad
settings and an address where no cluster answers are refused in one line before Ray starts."""

import contextlib
import dataclasses
import faulthandler
import json
import os
import pathlib
import re
import signal
import socket
import threading
import time

from handmade_exp1s import exp1s_record
import pytest
import ray
from ray import cluster_utils
import worker_hooks

from softbench import cli
from softbench import profiles
from softbench import records
from softbench import storage
from softbench import sweep
from softbench import zoo
from softbench.agents import learned
from softbench.continual import streams
from softbench.learning import exp1s as exp1s_training
from softbench.learning import protocols
from softbench.runners import continual
from softbench.runners import continual_stream
from softbench.runners import run
from softbench.sweep import builds as sweep_builds
from softbench.sweep import display
from softbench.sweep import execution
from softbench.sweep import grid as sweep_grid

GRID = sweep.Grid(("tendon-1",), ("circle", "reach"), ("mlp", "zero"), "tiny", 2)
VARYING = ("date", "machine", "git_commit", "wall_time_s", records.INTEGRITY_FIELD)  # May differ.
# (s) Longest a test may take, on a machine busy with other work: the longest took 165 s beside the
# other tests and a paper-profile training on 2 cores of an AMD EPYC.
TEST_SECONDS = 300
HARD_LIMIT_S = 30  # (s) Then, how long a test stuck in Ray's C++ code has before the process ends.
# (s) How often the killer reads every process's title: 3 to 4 ms of a core each time on the
# development machine, a sixth of a core for the test's minute at the 20 ms it was.
POLL_SECONDS = 0.05


@pytest.fixture(scope="module")
def address():
  """A Ray cluster on this machine, a head and one more node of one core each; its address.

  (Not on 127.0.0.1: ray.init rewrites a loopback address to the machine's own, where a head
  bound to the loopback interface does not answer.)"""
  cluster = cluster_utils.Cluster(
    initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False}
  )
  cluster.add_node(num_cpus=1)
  yield cluster.address
  cluster.shutdown()


@pytest.fixture(scope="module")
def expected(tmp_path_factory, with_babbled_dataset) -> dict[str, dict]:
  """``softbench run``'s record of every setting of GRID, by name, as its file holds it (run in a
  data home of its own, given the tiny datasets; the sweep's own home is not)."""
  home = tmp_path_factory.mktemp("run-home")
  for robot in GRID.robots:
    with_babbled_dataset(home, robot)
  with pytest.MonkeyPatch.context() as patch:
    patch.setenv(storage.HOME_VARIABLE, str(home))
    patch.setenv(zoo.VARIABLE, zoo.OFF)
    return {
      sweep_grid.setting_name(settings): json.loads(
        records.dumps(records.seal(run.execute(settings, show_progress=False, workers=1)))
      )
      for settings in GRID.settings()
    }


@pytest.fixture(autouse=True)
def bounded():
  """Fails a test that runs over TEST_SECONDS (raised in the main thread, as Ctrl-C would be),
  and ends the test process if it is stuck in Ray's own code HARD_LIMIT_S later."""

  def over(signal_number, frame):
    raise TimeoutError(f"the test ran over {TEST_SECONDS} s")

  previous = signal.signal(signal.SIGALRM, over)
  signal.alarm(TEST_SECONDS)
  faulthandler.dump_traceback_later(TEST_SECONDS + HARD_LIMIT_S, exit=True)
  yield
  faulthandler.cancel_dump_traceback_later()
  signal.alarm(0)
  signal.signal(signal.SIGALRM, previous)


@pytest.fixture(autouse=True)
def data_home(tmp_path, monkeypatch) -> pathlib.Path:
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  return tmp_path / "home"


def run_sweep(
  grid: sweep.Grid, results: pathlib.Path, address: str, show_progress: bool = False
) -> sweep.SweepResult:
  return sweep.sweep(
    grid.robots,
    grid.tasks,
    grid.agents,
    results,
    grid.profile,
    grid.seeds,
    grid.eval_modes,
    address,
    show_progress=show_progress,
    families=grid.families,
    streams=grid.streams,
    strategies=grid.strategies,
  )


def name_of(record: dict) -> str:
  """The record's setting, as ``grid.setting_name`` names it."""
  return "-".join(record[field] for field in ("agent", "robot", "task", "profile", "eval_mode"))


def assert_records_as_run(results: pathlib.Path, grid: sweep.Grid, expected: dict) -> None:
  """``results`` holds one record of each setting of ``grid``, equal to ``softbench run``'s but
  for ``VARYING``."""
  written = [records.read(path) for path in results.glob("*.json")]
  assert sorted(map(name_of, written)) == sorted(map(sweep_grid.setting_name, grid.settings()))
  for record in written:
    assert {key: value for key, value in record.items() if key not in VARYING} == {
      key: value for key, value in expected[name_of(record)].items() if key not in VARYING
    }, name_of(record)


@contextlib.contextmanager
def killing_the_first(title: str):
  """Within the block, the first process whose title begins with ``title`` (a Ray worker
  running the task of that name) is killed with SIGKILL; yields the killed processes' ids."""
  killed, stop = [], threading.Event()

  def kill() -> None:
    while not stop.is_set():
      for pid in filter(str.isdigit, os.listdir("/proc")):
        with contextlib.suppress(OSError):
          if pathlib.Path("/proc", pid, "cmdline").read_bytes().startswith(title.encode()):
            os.kill(int(pid), signal.SIGKILL)
            killed.append(int(pid))
            return
      time.sleep(POLL_SECONDS)

  killer = threading.Thread(target=kill, daemon=True)
  killer.start()
  try:
    yield killed
  finally:
    stop.set()
    killer.join()


@contextlib.contextmanager
def ray_with_worker_hook(address: str, hook):
  """Within the block, this process's Ray (a sweep uses it) is connected to ``address`` with
  ``hook`` (of ``worker_hooks``) as the job's setup hook, which every Ray worker runs first;
  pickled by value, since a task's own runtime environment cannot carry one."""
  ray.cloudpickle.register_pickle_by_value(worker_hooks)
  ray.init(address=address, runtime_env={"worker_process_setup_hook": hook})
  try:
    yield
  finally:
    ray.shutdown()
    ray.cloudpickle.unregister_pickle_by_value(worker_hooks)


def test_a_killed_worker_is_retried_and_a_task_that_raises_fails_only_its_setting(
  address, expected, tmp_path
):
  # One sweep for both faults: mlp's agent build is killed once, every zero evaluation raises.
  results, mlp_and_zero = tmp_path / "results", dataclasses.replace(GRID, tasks=("circle",))
  with (
    ray_with_worker_hook(address, worker_hooks.break_zero_evaluations),
    killing_the_first("ray::agent mlp tendon-1 seed 1") as killed,
    pytest.raises(sweep.SweepFailed) as raised,
  ):
    run_sweep(mlp_and_zero, results, None)
  assert len(killed) == 1
  message = str(raised.value)
  assert message.startswith("1 of 2 settings failed") and "\n" not in message
  assert f"zero-tendon-1-circle-tiny-physics: RuntimeError: {worker_hooks.BROKEN}" in message
  assert_records_as_run(results, dataclasses.replace(mlp_and_zero, agents=("mlp",)), expected)
  rerun = run_sweep(mlp_and_zero, results, address)  # Retries the failed setting.
  assert len(rerun.skipped) == 1 and len(rerun.written) == 1
  assert_records_as_run(results, mlp_and_zero, expected)


def test_an_interrupted_sweep_resumes_to_the_records_softbench_run_writes(
  address, expected, tmp_path, monkeypatch, capsys
):
  # One test for four properties, since each needs whole sweeps on the cluster: the records
  # equal softbench run's, an interrupted sweep resumes, settings with a record are skipped, and
  # the display shows the workers' bars (in a log: each one's last state, at the end).
  results, settings = tmp_path / "results", len(GRID.settings())
  update = display.Display.update

  def interrupted_after_the_first_record(shown, done, running, failed, written):
    update(shown, done, running, failed, written)
    if 1 <= written < settings:  # kill ends it as Ctrl-C does (ray.init's own handler aborted).
      os.kill(os.getpid(), signal.SIGTERM)

  with monkeypatch.context() as patch:
    patch.setattr(display.Display, "update", interrupted_after_the_first_record)
    with pytest.raises(KeyboardInterrupt):
      run_sweep(GRID, results, address, show_progress=True)
  assert not ray.is_initialized()
  first = sorted(results.glob("*.json"))
  assert 1 <= len(first) < settings
  capsys.readouterr()
  resumed = run_sweep(GRID, results, address, show_progress=True)
  shown = capsys.readouterr()
  episodes = re.findall(r"^\w+ seed [01] on (?:circle|reach): 4/4, .* elapsed$", shown.out, re.M)
  assert episodes, shown.out  # A worker's last episode (the tiny profile's: 4 steps).
  assert sorted(resumed.skipped) == first
  assert len(resumed.written) == settings - len(first)
  assert_records_as_run(results, GRID, expected)
  assert not ray.is_initialized()  # The sweep left the cluster.
  assert not list(storage.softbench_home().glob("runs/*"))  # No kept episodes: records are in.
  assert run_sweep(GRID, results, address).written == ()  # Nothing left: Ray is not started.


def test_exp1s_in_a_sweep_writes_the_record_softbench_run_writes(
  address, tmp_path, with_babbled_dataset
):
  tiny, family = profiles.get("tiny"), "tendon-local"
  only_exp1s = sweep.Grid((), (), (), "tiny", 1, families=(family,))
  with (
    pytest.MonkeyPatch.context() as patch,
    ray_with_worker_hook(address, worker_hooks.shorten_exp1s),
  ):
    patch.setitem(protocols.PROTOCOLS, continual.PROTOCOL, worker_hooks.shortened_exp1s())
    for stage in exp1s_training.protocol(family).robot_names:  # Given to softbench run's home only.
      with_babbled_dataset(tmp_path / "run-home", stage)
    with pytest.MonkeyPatch.context() as home:  # softbench run's record, in a home of its own.
      home.setenv(storage.HOME_VARIABLE, str(tmp_path / "run-home"))
      expected = records.seal(continual.execute(tiny, 1, False, workers=1, family=family))
    (path,) = run_sweep(only_exp1s, tmp_path / "results", None).written
    assert not continual.finished_seeds_folder(tiny, family).exists()  # The record is in.
  assert path.name.startswith(f"smpl-exp1s-{family}-tiny-")
  assert path.with_name(f"{path.stem}-forgetting.png").stat().st_size > 0
  assert {key: value for key, value in records.read(path).items() if key not in VARYING} == {
    key: value for key, value in json.loads(records.dumps(expected)).items() if key not in VARYING
  }
  assert run_sweep(only_exp1s, tmp_path / "results", address).skipped == (path,)


@pytest.mark.parametrize(
  "change,message",
  [
    ({"tasks": ("juggle",)}, "unknown task"),
    ({"agents": ("oracle",)}, "unknown agent"),
    ({"robots": ("tendon-0",)}, "1 to 10 modules"),
    ({"profile": "huge"}, "unknown profile"),
    ({"eval_modes": ("dream",)}, "unknown eval mode"),
    ({"seeds": 0}, "seeds must be"),
    ({"agents": ()}, "at least one of its agents"),
    ({"families": ("pneumatic",)}, "unknown tendon family"),
    ({"robots": (), "tasks": (), "agents": (), "families": ("tendon",), "seeds": 0}, "seeds must"),
  ],
)
def test_bad_settings_are_one_line_before_ray_starts(change, message, tmp_path):
  with pytest.raises(ValueError, match=message) as raised:
    run_sweep(dataclasses.replace(GRID, **change), tmp_path / "results", None)
  assert "\n" not in str(raised.value) and not ray.is_initialized()


def test_an_address_where_no_cluster_answers_is_one_line(tmp_path):
  zero = dataclasses.replace(GRID, agents=("zero",))
  with pytest.raises(ValueError, match="no Ray cluster answers at 127.0.0.1:1 "):
    run_sweep(zero, tmp_path / "results", "127.0.0.1:1")
  with pytest.raises(ValueError, match="HOST:PORT"):
    run_sweep(zero, tmp_path / "results", "head-without-port")
  assert not ray.is_initialized()


def test_without_an_address_the_sweep_starts_its_own_ray_whatever_ray_address_says(
  address, tmp_path, monkeypatch
):
  monkeypatch.setenv("RAY_ADDRESS", address)  # Ray's own default: join the cluster it names.
  zero = dataclasses.replace(GRID, tasks=("circle",), agents=("zero",), seeds=1)
  (written,) = run_sweep(zero, tmp_path / "results", None).written
  assert records.read(written)["agent"] == "zero"  # Before: ray.init refused num_cpus there.
  assert not ray.is_initialized()


def test_an_address_where_something_else_answers_is_one_line(tmp_path, monkeypatch, capsys):
  def refused(address):  # What ray.init raises after about 20 s of retries there.
    raise ConnectionError(f"Failed to connect to Ray cluster at {address}")

  monkeypatch.setattr(ray, "init", refused)
  with socket.create_server(("", 0)) as listener:  # Answers, but is no Ray head.
    address = f"127.0.0.1:{listener.getsockname()[1]}"
    argv = ["sweep", "--robots", "tendon-1", "--tasks", "circle", "--agents", "zero"]
    assert cli.main([*argv, "--address", address, "--results", str(tmp_path)]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.count("\n") == 1 and f"no Ray cluster at {address}: something answers" in error


def test_a_record_stands_for_its_setting_only_with_its_seeds_and_target_completion(
  expected, tmp_path
):
  results, name = tmp_path / "results", "mlp-tendon-1-reach-tiny-physics"
  results.mkdir()
  reach = dataclasses.replace(GRID, tasks=("reach",), agents=("mlp",))
  made = expected[name]
  assert made["seeds"] == 2 and made["helpers"] == learned.DEFAULT_HELPER_TARGETS
  held = {**made, "helpers": "hold"}  # As a reach made before target completion, or --helpers hold.
  one_seed = {
    **made,
    "seeds": 1,
    "per_seed": made["per_seed"][:1],
    "weights": {"per_seed": made["weights"]["per_seed"][:1]},
  }
  for day, record in ((1, held), (2, one_seed)):
    records.write(record, results / f"{name}-2026-11-0{day}T000000Z.json")
  assert sweep_grid.plan(reach, results).skipped == ()
  damaged = results / f"{name}-2026-11-03T000000Z.json"
  damaged.write_text("{")
  with pytest.raises(records.RecordError, match=f"{damaged}: not valid JSON") as raised:
    sweep_grid.plan(reach, results)
  assert "\n" not in str(raised.value)
  records.write(made, damaged)
  assert sweep_grid.plan(reach, results).skipped == (damaged,)


def test_a_dry_run_lists_the_settings_without_records_and_runs_nothing(expected, tmp_path, capsys):
  results, name = tmp_path / "results", "mlp-tendon-1-circle-tiny-physics"
  argv = ["sweep", "--robots", "tendon-1", "--tasks", "circle", "--agents", "zero", "mlp"]
  argv += ["--profile", "tiny", "--seeds", "2", "--results", str(results), "--dry-run"]
  assert cli.main(argv) == 0
  assert capsys.readouterr().out.splitlines() == [
    "2 settings to run, 0 with records skipped",
    "  zero-tendon-1-circle-tiny-physics: 2 of 2 seeds",
    "  mlp-tendon-1-circle-tiny-physics: 2 of 2 seeds",
    "to build: dataset 1, forward 2, agent 2, network 0, stages 0 (0 resuming an unfinished "
    "training, run first); found in the data home: 0",
  ]
  assert not ray.is_initialized() and not list(results.glob("*"))
  assert not list(storage.softbench_home().glob("*/*"))  # Nothing built.
  records.write(expected[name], results / f"{name}-2026-11-24T000000Z.json")
  assert cli.main(argv) == 0
  assert capsys.readouterr().out.splitlines()[:2] == [
    "1 settings to run, 1 with records skipped",
    "  zero-tendon-1-circle-tiny-physics: 2 of 2 seeds",
  ]


def test_trainings_under_way_are_submitted_before_new_ones(data_home, tmp_path):
  grid = dataclasses.replace(GRID, tasks=("circle",), agents=("mlp",))

  def order() -> list[str]:
    plan = sweep_grid.plan(grid, tmp_path / "results")
    labels = [build.label for build in plan.builds]
    for build in plan.builds:  # Each after what it needs.
      assert all(labels.index(need.label) < labels.index(build.label) for need in build.needs)
    return [build.label for build in plan.builds if build.kind == "agent"]

  assert order() == ["agent mlp tendon-1 seed 0", "agent mlp tendon-1 seed 1"]
  (seed_1,) = sweep_builds.agent_build("mlp", "tendon-1", 1, profiles.get("tiny")).files
  (data_home / seed_1).with_suffix(".partial").mkdir(parents=True)  # Its snapshots' folder.
  assert order() == ["agent mlp tendon-1 seed 1", "agent mlp tendon-1 seed 0"]
  report = sweep_grid.plan(grid, tmp_path / "results").report()
  assert "(1 resuming an unfinished training, run first)" in report


def test_evaluations_wait_while_the_runnable_builds_fill_every_core(tmp_path):
  """Ray shares cores fairly between kinds of task, so an evaluation submitted while trainings
  wait for a core would delay them: it is held until the runnable builds leave a core free."""
  grid = dataclasses.replace(GRID, tasks=("circle",), agents=("mlp", "zero"), seeds=3)
  plan = sweep_grid.plan(grid, tmp_path / "results")
  agents = [build for build in plan.builds if build.kind == "agent"]
  forward = {need for agent in agents for need in agent.needs}
  built = {need for build in forward for need in build.needs} | forward  # The agents' needs.
  held = list(plan.evaluations)
  baselines = [evaluation for evaluation in held if evaluation.agent is None]
  assert len(agents) == 3 and len(baselines) == 3

  def released(finished: set, cores: int) -> list:
    return execution.releasable(held, plan.builds, finished, cores, dict.fromkeys(plan.builds, 1))

  assert released(set(), cores=1) == []  # The dataset's collection fills the only core.
  assert released(set(), cores=2) == baselines  # It leaves one: those that need no agent.
  assert released(built, cores=2) == []  # Three trainings can run on two cores.
  assert released(built, cores=4) == baselines  # A core left: those that need no agent.
  assert released(built | {agents[0]}, cores=2) == []  # Two trainings still fill both cores.
  # One training left on two cores: the evaluations whose agents are built, not the third's.
  assert released(built | set(agents[:2]), cores=2) == [
    evaluation for evaluation in held if evaluation.agent is None or evaluation.agent in agents[:2]
  ]
  assert released(built | set(agents), cores=1) == held  # Every build done: all of them.


def test_an_exp1s_record_stands_for_its_own_family_only(tmp_path):
  results = tmp_path / "results"
  results.mkdir()
  records.write(  # The tendon family's.
    exp1s_record(seeds=1), results / "smpl-exp1s-tiny-2026-11-24T000000Z.json"
  )
  work = sweep_grid.plan(
    sweep.Grid((), (), (), "tiny", 1, families=("tendon", "tendon-local")), results
  )
  assert work.skipped == (results / "smpl-exp1s-tiny-2026-11-24T000000Z.json",)
  assert [sweep_grid.setting_name(run) for run in work.settings] == ["smpl-exp1s-tendon-local-tiny"]
  (evaluation,) = work.evaluations
  assert evaluation.agent.kind == "network"
  assert [need.label for need in evaluation.agent.needs] == [
    f"babbling tendon-local-{n} 200 samples" for n in range(1, 6)
  ]


def test_continual_runs_in_a_sweep_write_the_record_softbench_run_writes(
  address, tmp_path, with_babbled_dataset, monkeypatch
):
  tiny, pair = profiles.get("tiny"), worker_hooks.pair_stream()
  monkeypatch.setattr(streams, "_STREAMS", {**streams._STREAMS, pair.name: pair})
  monkeypatch.setattr(streams, "STREAMS", (*streams.STREAMS, pair.name))
  grid = sweep.Grid((), (), (), "tiny", 1, streams=(pair.name,), strategies=("independent",))
  run = continual_stream.ContinualSettings("independent", pair.name, "tendon", tiny, 1)
  for stage in worker_hooks.PAIR_STAGES:
    with_babbled_dataset(tmp_path / "run-home", stage)
  with pytest.MonkeyPatch.context() as home:  # softbench run's record, in a home of its own.
    home.setenv(storage.HOME_VARIABLE, str(tmp_path / "run-home"))
    expected = records.seal(continual_stream.execute(run, show_progress=False, workers=1))
  with ray_with_worker_hook(address, worker_hooks.register_pair_stream):
    (path,) = run_sweep(grid, tmp_path / "results", None).written
  assert path.name.startswith("independent-continual-pair-tiny-")
  assert path.with_name(f"{path.stem}-matrix.png").stat().st_size > 0
  made = records.read(path)
  for entry in (made, expected):  # Wall times differ; everything else is the same.
    for seed in entry["per_seed"]:
      for stage in seed["stages"]:
        stage["training_seconds"] = 0
  varying = (*VARYING, "per_seed")
  assert {key: value for key, value in made.items() if key not in varying} == {
    key: value for key, value in json.loads(records.dumps(expected)).items() if key not in varying
  }
  assert made["per_seed"] == json.loads(json.dumps(expected["per_seed"]))
  assert not continual_stream.episodes_folder(run).exists()  # The record is in.
  work = sweep_grid.plan(grid, tmp_path / "results")
  assert work.skipped == (path,) and not work.settings


def test_a_continual_setting_plans_its_stages_from_the_stream_s_datasets(tmp_path):
  grid = sweep.Grid((), (), (), "tiny", 2, streams=("degrade",), strategies=("ewc", "smpl"))
  work = sweep_grid.plan(grid, tmp_path / "results")
  assert [sweep_grid.setting_name(run) for run in work.settings] == [
    "ewc-continual-degrade-tiny",
    "smpl-continual-degrade-tiny",
  ]
  assert len(work.evaluations) == 4
  stages = work.evaluations[0].agent
  assert stages.kind == "stages" and len(stages.files) == len(streams.DEGRADE_GAINS)
  assert [need.label for need in stages.needs] == [
    "babbling tendon-3 200 samples",
    *(
      "babbling tendon-3"
      + "".join(f" fault 3:{cable}:{gain:g}" for cable in range(4))
      + " 200 samples"
      for gain in streams.DEGRADE_GAINS[1:]
    ),
  ]


@pytest.mark.parametrize(
  "argv,message",
  [
    (["--families", "tendon"], "--families goes with --protocol exp1s"),
    (["--protocol", "exp2s"], "unknown protocol 'exp2s'"),
    (["--protocol", "exp1s", "--families", "pneumatic"], "unknown tendon family 'pneumatic'"),
    (["--protocol", "exp1s", "--robots", "tendon-1"], "at least one of its tasks"),
    (["--streams", "grow"], "--streams goes with --protocol continual"),
    (["--protocol", "continual", "--agents", "ewc"], "needs --streams"),
    (["--protocol", "continual", "--streams", "grow"], "at least one of its strategies"),
    (["--protocol", "continual", "--streams", "up", "--agents", "ewc"], "unknown stream 'up'"),
    (["--protocol", "continual", "--streams", "grow", "--agents", "mlp"], "strategy 'mlp'"),
    (["--protocol", "continual", "--streams", "grow", "--robots", "tendon-1"], "drop --robots"),
  ],
)
def test_the_cli_refuses_bad_protocol_options_in_one_line(argv, message, tmp_path, capsys):
  assert cli.main(["sweep", *argv, "--results", str(tmp_path / "results")]) == 2
  error = capsys.readouterr().err
  assert message in error and error.count("\n") == 1
  assert not ray.is_initialized()


def test_a_local_ray_that_does_not_start_is_a_one_line_failure(tmp_path, monkeypatch, capsys):
  """Seen on 2026-12-07: Ray's node timed out at startup (its processes were held up) and the
  sweep ended in Ray's traceback."""

  def timed_out(*args, **kwargs):
    raise Exception("The current node timed out during startup. This could happen because ...")

  monkeypatch.setattr(ray, "init", timed_out)
  argv = ["sweep", "--robots", "tendon-1", "--tasks", "circle", "--agents", "zero"]
  assert cli.main([*argv, "--profile", "tiny", "--results", str(tmp_path / "results")]) == 1
  error = capsys.readouterr().err
  assert "the local Ray did not start (The current node timed out during startup." in error
  assert error.count("\n") == 1 and not ray.is_initialized()
