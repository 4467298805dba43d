"""The committed models regenerate byte for byte; the CLI lists robots and refuses bad input."""

import json
import os
import pathlib
import subprocess
import sys

import mujoco
import numpy as np
import pytest

import softbench
from softbench import agents
from softbench import cli
from softbench import data
from softbench import robots
from softbench import storage
from softbench import suite
from softbench.agents import hyperparameters
from softbench.robots import export
from softbench.robots import versions
from softbench.robots.physics import SoftArmPhysics
from softbench.runners import run

MODELS = pathlib.Path(__file__).resolve().parents[1] / "models"


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_committed_models_are_identical_to_regenerated(name):
  for file_name, text in export.model_files(robots.make(name)).items():
    assert (MODELS / name / file_name).read_text() == text, file_name


# Measuring a README's figures takes seconds to minutes per robot (the discretisation check
# simulates a 4x finer arm); the smallest robot of each tendon family shows that the
# measurements reproduce (tendon-2 took 4 times tendon-1's 4 s).
@pytest.mark.parametrize("name", ["tendon-1", "tendon-local-1"])
def test_committed_model_readme_is_identical_to_regenerated(name):
  speed = json.loads((MODELS / name / export.SPEED_FILE).read_text())
  assert (MODELS / name / "README.md").read_text() == export.readme(robots.make(name), speed)


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_committed_model_readme_wraps_its_prose(name):
  lines = (MODELS / name / "README.md").read_text().splitlines()
  long = [line for line in lines if len(line) > export.README_COLUMNS and line[:1] not in "|#"]
  assert long == []


def test_cli_export_writes_every_registered_model(tmp_path, monkeypatch):
  monkeypatch.setattr(export, "readme", lambda robot, speed: f"# {robot.name}\n")
  assert cli.main(["models", "export", "--out", str(tmp_path)]) == 0
  written = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*") if p.is_file())
  assert written == sorted(
    f"{name}/{file}"
    for name in robots.REGISTERED_ROBOTS
    for file in (f"{name}.xml", "scene.xml", "README.md")
  )


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_exported_scene_compiles(name):
  model = mujoco.MjModel.from_xml_path(str(MODELS / name / "scene.xml"))
  assert model.nu == len(robots.make(name).actuator_maps())
  assert model.geom("floor").id >= 0


@pytest.mark.parametrize(
  "name",
  [
    name
    for name in robots.REGISTERED_ROBOTS
    if name.startswith("tendon-local-") and robots.make(name).num_modules >= 3
  ],
)
def test_exported_local_arm_bends_only_the_pulled_module(name):
  # Gravity off, one cable of module 3 pulled at Tmax for 3 s, on the exported scene as a user
  # loads it: module 1's tip turns 0.0 deg, module 3's 91.2 deg (tendon-3: 30.6 and 152.4 deg).
  physics = SoftArmPhysics.from_xml_path(str(MODELS / name / "scene.xml"))
  physics.model.opt.gravity[:] = 0.0
  rest = physics.module_poses()[:, 3:]
  action = np.zeros(physics.action_dim)
  action[4] = 1.0  # Module 3's x axis: its +x cable at Tmax.
  physics.set_action(action)
  physics.step(int(round(3.0 / physics.model.opt.timestep)))
  axes = physics.module_poses()[:, 3:]
  turned = np.degrees(np.arccos(np.clip(np.sum(axes * rest, axis=1), -1.0, 1.0)))
  assert turned[0] <= 1.0 and turned[2] >= 45.0, turned


def test_cli_lists_every_registered_robot_and_names_the_leaderboards(capsys):
  assert cli.main(["robots"]) == 0
  table, footer = capsys.readouterr().out.split("\n\n")
  rows = table.splitlines()[1:]
  assert [row.split()[0] for row in rows] == list(robots.REGISTERED_ROBOTS)
  assert rows[0].split()[1:3] == ["1", "2"]  # tendon-1: one module, two action entries.
  assert footer.startswith(f"{len(rows)} registered robots")
  assert footer.strip().endswith("ranks agents on tendon-3, tendon-local-3, pneumatic-433")


@pytest.mark.parametrize(
  "argv,line",
  [
    (
      ["run", "--task", "spiral", "--agent", "zero", "--seed", "2"],
      "softbench run: error: unrecognized arguments: --seed 2; did you mean --seeds? "
      "(see softbench run --help)",
    ),
    (
      ["render", "--task", "spiral", "--agent", "zero", "--seeds", "2", "--out", "x.mp4"],
      "softbench render: error: unrecognized arguments: --seeds 2; did you mean --seed? "
      "(see softbench render --help)",
    ),
    (
      ["run", "--task", "spiral", "--agent", "zero", "--prof", "tiny"],  # No abbreviations.
      "softbench run: error: unrecognized arguments: --prof tiny; did you mean --profile? "
      "(see softbench run --help)",
    ),
    (
      ["leaderboard", "--robot", "tendon-3"],
      "softbench leaderboard: error: unrecognized arguments: --robot tendon-3; did you mean "
      "--robots? (see softbench leaderboard --help)",
    ),
  ],
)
def test_an_unknown_option_is_the_commands_error_with_the_option_meant(argv, line, capsys):
  assert cli.main(argv) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  assert captured.out == "" and captured.err == line + "\n"


def test_cli_lists_robots_tasks_and_agents_as_json(capsys):
  assert cli.main(["robots", "--json"]) == 0
  listed = json.loads(capsys.readouterr().out)
  assert [robot["name"] for robot in listed] == list(robots.REGISTERED_ROBOTS)
  for facts in listed:
    arm = robots.make(facts["name"])
    assert facts["action_dim"] == arm.action_dim == sum(facts["actuators_per_module"])
    assert (facts["modules"], facts["length_m"]) == (arm.num_modules, arm.length)
  assert cli.main(["robots", "tendon-7", "--json"]) == 0
  described = json.loads(capsys.readouterr().out)
  assert described["modules"] == 7 and described["spec"]["backbone"] == versions.current().backbone
  assert cli.main(["tasks", "--json"]) == 0
  tasks = json.loads(capsys.readouterr().out)
  assert [task["name"] for task in tasks] == list(suite.TASKS)
  pairs = {(robot, task["name"]) for task in tasks for robot in task["registered_robots"]}
  assert pairs == set(suite.ALL_TASKS)
  assert cli.main(["agents", "--json"]) == 0
  listed_agents = json.loads(capsys.readouterr().out)
  assert [agent["name"] for agent in listed_agents] == list(agents.AGENTS)
  for agent in listed_agents:
    assert agent["learned"] == agents.describe(agent["name"]).learned
    assert bool(agent["hyperparameters"]) == (
      agent["learned"] and agent["name"] in hyperparameters.load()["agents"]
    )


def test_cli_tables_are_plain_lines_when_piped(capsys):
  # capsys is not a terminal: one line a row however long, no escape codes, no trailing spaces.
  assert cli.main(["agents", "--verbose"]) == 0
  lines = capsys.readouterr().out.splitlines()
  tuned = hyperparameters.load()["agents"]
  learned = [name for name in agents.AGENTS if agents.describe(name).learned]
  assert len(lines) == 1 + len(agents.AGENTS) + sum(len(tuned.get(name, {})) for name in learned)
  assert all(line == line.rstrip() and "\x1b" not in line for line in lines)


def test_cli_describes_any_valid_tendon_arm(capsys):
  assert cli.main(["robots", "tendon-7"]) == 0
  assert capsys.readouterr().out.splitlines()[1].split()[:3] == ["tendon-7", "7", "14"]


@pytest.mark.parametrize(
  "argv",
  [
    ["robots", "tendon-0"],
    ["robots", "tendon-x"],
    ["robots", "tendon-1000"],
    ["robots", "tendon-local-0"],
    ["robots", "tendon-local-x"],
    ["robots", "tendon-local-"],
    ["robots", "unicorn"],
    ["robots", "tendon-3", "--module-length", "-0.05"],
  ],
)
def test_cli_refuses_bad_input_with_one_line_and_exit_code_2(argv, capsys):
  assert cli.main(argv) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  assert captured.out == ""
  lines = captured.err.strip().splitlines()
  assert len(lines) == 1 and lines[0].startswith("softbench: error: ")
  with pytest.raises(ValueError, match=lines[0].removeprefix("softbench: error: ")[:20]):
    robots.make(argv[1], **({"module_length": -0.05} if len(argv) > 2 else {}))


def test_cli_export_refuses_a_bad_robot_before_writing(tmp_path, capsys):
  argv = [
    "models",
    "export",
    "--out",
    str(tmp_path),
    "--robots",
    "tendon-local-1",
    "tendon-local-0",
  ]
  assert cli.main(argv) == cli.EXIT_USAGE
  assert capsys.readouterr().err.strip() == (
    "softbench: error: tendon-local arms have 1 to 10 modules, got 0"
  )
  assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("length", ["80", "1e-6", "1e9"])
def test_cli_refuses_a_module_length_out_of_range(length, capsys):
  # 80 is a typo for 80 mm; 1e-6 m made MuJoCo's two-line compile error.
  assert cli.main(["robots", "pneumatic-433", "--module-length", length]) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  assert captured.out == ""
  assert captured.err.count("\n") == 1 and "module_length must lie between" in captured.err


def test_cli_lists_every_task_and_the_control_periods(capsys):
  assert cli.main(["tasks"]) == 0
  out = capsys.readouterr().out
  for task in suite.TASKS:
    assert f"\n{task} " in out
  assert "tendon arms 1 s (1 Hz)" in out and "pneumatic arms 0.2 s (5 Hz)" in out


def test_cli_collects_a_dataset_then_finds_it(tmp_path, monkeypatch, capsys):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  argv = ["collect", "--robot", "tendon-1", "--samples", "20", "--seed", "3", "--workers", "1"]
  assert cli.main(argv) == 0
  first = capsys.readouterr().out.splitlines()
  assert first[0].startswith("tendon-1: 20 samples in 1 episodes")
  folder = pathlib.Path(first[1])
  assert (folder / "dataset.npz").exists() and folder.is_relative_to(tmp_path)
  before = (folder / "dataset.npz").read_bytes()
  assert cli.main(argv) == 0
  assert capsys.readouterr().out.splitlines()[1] == first[1]
  assert (folder / "dataset.npz").read_bytes() == before


@pytest.mark.parametrize(
  "argv",
  [
    ["collect", "--robot", "tendon-0"],
    ["collect", "--robot", "unicorn"],
    ["collect", "--robot", "tendon-2", "--samples", "0"],
    ["collect", "--robot", "tendon-2", "--seed", "-1"],
    ["collect", "--robot", "tendon-2", "--workers", "0"],
    ["collect", "--robot", "tendon-2", "--samples", "100000000000000"],  # Would fill the memory.
  ],
)
def test_cli_collect_refuses_bad_input(argv, capsys, tmp_path, monkeypatch):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  assert cli.main(argv) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and lines[0].startswith("softbench: error: ")
  assert not (tmp_path / "datasets").exists()


@pytest.mark.parametrize("backend", ["bogus"])
def test_an_opengl_backend_mujoco_cannot_load_is_one_line(backend):
  environment = {**os.environ, "MUJOCO_GL": backend}
  result = subprocess.run(
    [sys.executable, "-m", "softbench.launcher", "robots"],
    env=environment,
    capture_output=True,
    text=True,
    timeout=120,
  )
  assert result.returncode == cli.EXIT_USAGE
  assert result.stderr.count("\n") == 1 and f"MUJOCO_GL='{backend}'" in result.stderr


def test_an_egl_that_cannot_open_falls_back_to_osmesa_or_says_what_to_install(
  broken_egl_environment, launch_with_broken_egl
):
  installed = softbench.installed_headless_backends()
  if "egl" not in installed:
    pytest.skip("EGL's library is not installed here, so softbench does not choose it")
  probe = subprocess.run(
    [sys.executable, "-c", "from dm_control import _render"],
    env={**os.environ, **broken_egl_environment, "MUJOCO_GL": "egl"},
    capture_output=True,
    timeout=120,
  )
  if probe.returncode == 0:
    pytest.skip("EGL opens here even without its vendor files")
  result = launch_with_broken_egl(["robots"])
  if "osmesa" in installed:  # softbench starts again with OSMesa.
    assert result.returncode == 0, result.stderr
    assert "tendon-3" in result.stdout and "Traceback" not in result.stderr
  else:  # Nothing left to try: one line naming both the failure and what to install.
    assert result.returncode == cli.EXIT_USAGE
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("softbench: error: ")
    assert "MUJOCO_GL='egl'" in result.stderr and "libosmesa6" in result.stderr


def test_a_closed_pipe_is_not_a_traceback(monkeypatch):
  read_end, write_end = os.pipe()
  os.close(read_end)  # The reader went away, as `softbench robots | head -1` does.
  with os.fdopen(write_end, "w", buffering=1) as closed:
    monkeypatch.setattr(sys, "stdout", closed)
    assert cli.main(["robots"]) == cli.EXIT_FAILURE


def _read_only_file_system(*args, **kwargs):
  raise OSError(30, "Read-only file system")


@pytest.mark.parametrize("home", ["/dev/null", "under-a-file", "/proc/softbench", "read-only"])
@pytest.mark.parametrize(
  "command",
  [
    ["run", "--task", "circle", "--agent", "zero", "--robot", "tendon-1", "--profile", "tiny"],
    ["collect", "--robot", "tendon-1", "--samples", "10"],
    ["render", "--task", "circle", "--agent", "zero", "--robot", "tendon-1", "--out", "x.mp4"],
  ],
)
def test_a_data_home_that_takes_no_file_is_refused_before_any_work(
  home, command, tmp_path, monkeypatch, capsys
):
  if home == "under-a-file":
    (tmp_path / "file").write_text("")
    home = str(tmp_path / "file" / "home")
  elif home == "read-only":
    home = str(tmp_path / "home")
    monkeypatch.setattr(storage.tempfile, "TemporaryFile", _read_only_file_system)
  monkeypatch.setenv(storage.HOME_VARIABLE, home)
  for name in ("execute_episodes", "seed_episode"):
    monkeypatch.setattr(run, name, _read_only_file_system)  # No work may start.
  monkeypatch.setattr(data, "collect", _read_only_file_system)
  results = ["--results", str(tmp_path / "results")] if command[0] == "run" else []
  assert cli.main([*command, *results]) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.startswith("softbench: error: cannot write the data home") and error.count("\n") == 1


@pytest.mark.parametrize(
  "argv",
  [
    ["models", "export", "--out", "/etc/hostname"],
    [
      "run",
      "--task",
      "circle",
      "--agent",
      "zero",
      "--robot",
      "tendon-1",
      "--profile",
      "tiny",
      "--results",
      "/proc/results",
    ],
  ],
)
def test_outputs_that_take_no_file_are_refused_before_any_work(argv, monkeypatch, capsys):
  monkeypatch.setattr(run, "execute_episodes", _read_only_file_system)
  assert cli.main(argv) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert error.startswith("softbench: error: cannot write") and error.count("\n") == 1
