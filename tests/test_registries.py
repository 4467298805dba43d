"""Registries own their entries: an example learned baseline (``example_agent.py``) and an example
task (``example_task.py``) each join by one registry line, and then build, train, run and score
through the same code as the built-in ones. Registration is undone after each test."""

import dataclasses
import json
import os
import subprocess
import sys

import example_task
import gymnasium
import numpy as np
import pytest

from softbench import agents
from softbench import cli
from softbench import profiles
from softbench import robots
from softbench import suite
from softbench.agents import hyperparameters
from softbench.agents import learned
import softbench.envs
from softbench.runners import evaluation

ROBOT = "tendon-1"


@pytest.fixture
def restored_registries(monkeypatch, restored_tasks):
  """The agent and task registries (and Gymnasium's ids) as they were, after the test."""
  monkeypatch.setattr(agents, "_AGENTS", dict(agents._AGENTS))
  monkeypatch.setattr(agents, "AGENTS", agents.AGENTS)


def _register_examples() -> None:
  # The one registry entry each addition takes (in the package: a line of agents._AGENTS or a
  # suite.register call):
  agents.register(
    "linear",
    agents.AgentEntry(
      None, True, "linear inverse model", agents.Learner(False, "example_agent:LinearInverse")
    ),
  )
  suite.register(
    "hold",
    suite.TaskEntry(
      build=example_task.Hold,
      tags=("benchmarking",),
      description="hold the starting pose",
      paper_robot="tendon-3",
      length_option="steps",
    ),
  )


def test_an_example_agent_and_task_join_by_one_line_each(
  restored_registries, tmp_path, monkeypatch
):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  _register_examples()
  assert "linear" in agents.AGENTS and "linear" in agents.babbling_learners()
  assert ("tendon-3", "hold") in suite.BENCHMARKING and "hold" in suite.TASKS
  assert hyperparameters.values("linear", ROBOT) == {}  # No entry: the model's defaults.
  agent = agents.make("linear", ROBOT, seed=0, profile="tiny")
  assert isinstance(agent, learned.LearnedAgent)
  path = learned.checkpoint_path(
    "linear", robots.make(ROBOT), 0, profiles.get("tiny"), per_module=False
  )
  assert path.is_file() and path.name.startswith(f"linear-{ROBOT}-seed0-")
  env = suite.load(ROBOT, "hold", seed=1, **suite.length_options("hold", 5))
  episode = evaluation.run_episode(env, agent, "hold")
  assert episode.actions.shape == (5, robots.make(ROBOT).action_dim)
  np.testing.assert_array_equal(episode.targets[0], episode.poses[0])  # The start, held.
  assert np.isfinite(episode.score(robots.make(ROBOT).length).average("position_mm").mean)
  # softbench.envs was imported before the task was registered, and gives it ids all the same.
  assert softbench.envs.env_id("tendon-3", "hold") in softbench.envs.env_ids()
  env = gymnasium.make(softbench.envs.env_id("tendon-3", "hold"), steps=2)
  observation, _ = env.reset(seed=0)
  assert env.step(env.action_space.sample())[0].shape == observation.shape
  env.close()


def test_registration_is_undone_between_tests():
  assert "linear" not in agents.AGENTS and "hold" not in suite.TASKS
  assert softbench.envs.env_id("tendon-3", "hold") not in gymnasium.registry


@pytest.mark.parametrize(
  "register,message",
  [
    (
      lambda: agents.register("zero", agents.AgentEntry("softbench.agents.zero", False, "again")),
      "registered already",
    ),
    (lambda: agents.register("My Agent", agents.AgentEntry("x", False, "")), "lowercase"),
    (
      lambda: agents.register("both", agents.AgentEntry("x", True, "", agents.Learner(True))),
      "either the module",
    ),
    (lambda: suite.register("spiral", suite.describe("spiral")), "registered already"),
    (
      lambda: suite.register(
        "new", dataclasses.replace(suite.describe("spiral"), paper_robot="octopus")
      ),
      "unknown robot",
    ),
    (lambda: suite.register("new", ("build", (), "", "tendon-3", None)), "a TaskEntry"),
    (
      lambda: suite.register("new", dataclasses.replace(suite.describe("reach"), build="reach")),
      "paths are module:name",
    ),
    (lambda: suite.tracking_task("no default")(lambda length, laps: length), "needs a default"),
    (lambda: suite.tracking_task("robot first", planar=False)(lambda length: 0), "must take"),
    (
      lambda: suite.tracking_task("an array")(lambda length, size=np.ones(2): length),
      "numbers, strings",
    ),
  ],
)
def test_a_bad_registration_is_refused_with_one_line(register, message, restored_registries):
  with pytest.raises(ValueError, match=message) as error:
    register()
  assert "\n" not in str(error.value)


def test_a_builder_path_that_names_nothing_is_one_line_when_the_task_is_built(restored_registries):
  # A path is imported only when the task is built, so registering it loads nothing.
  entry = dataclasses.replace(suite.describe("reach"), build="softbench.suite.nowhere:Reach")
  suite.register("nowhere", entry)
  with pytest.raises(ValueError, match="cannot be imported") as error:
    suite.load("tendon-1", "nowhere")
  assert "\n" not in str(error.value)


_PLUGIN_MODULE = """
import numpy as np

from softbench import agents
from softbench.agents import base


class HoldStill(base.Agent):
  def act(self, observation):
    return np.asarray(observation["previous_action"])


def build(robot, seed, profile, show_progress=False):
  return HoldStill(robot, seed)


HOLD_STILL = agents.AgentEntry("hold_still_plugin", False, "keeps its last action")
NOT_AN_ENTRY = 3
"""


@pytest.fixture
def installed_plugin(tmp_path) -> dict:
  """The environment of a child process in which a package of agents is installed: its module and
  its dist-info, with one good entry point and one that names no ``AgentEntry``."""
  (tmp_path / "hold_still_plugin.py").write_text(_PLUGIN_MODULE)
  info = tmp_path / "hold_still_plugin-0.1.dist-info"
  info.mkdir()
  (info / "METADATA").write_text("Metadata-Version: 2.1\nName: hold-still-plugin\nVersion: 0.1\n")
  (info / "entry_points.txt").write_text(
    f"[{agents.ENTRY_POINT_GROUP}]\n"
    "hold-still = hold_still_plugin:HOLD_STILL\n"
    "broken = hold_still_plugin:NOT_AN_ENTRY\n"
  )
  return {**os.environ, "PYTHONPATH": str(tmp_path), "SOFTBENCH_HOME": str(tmp_path / "home")}


def test_an_installed_packages_agent_runs_from_the_command_line(
  installed_plugin, tmp_path, monkeypatch, restored_registries, capsys
):
  # In seed workers too (--workers 2): they register the installed agents as the parent does.
  softbench = [sys.executable, "-c", "import sys; from softbench import cli; sys.exit(cli.main())"]
  run = ["run", "--task", "circle", "--agent", "hold-still", "--robot", ROBOT, "--profile", "tiny"]
  run += ["--seeds", "2", "--workers", "2", "--results", str(tmp_path / "results")]
  result = subprocess.run(
    softbench + run, env=installed_plugin, capture_output=True, text=True, timeout=600
  )
  assert result.returncode == 0, result.stderr
  (record,) = (tmp_path / "results").glob("hold-still-*.json")
  assert json.loads(record.read_text())["agent"] == "hold-still"
  warning = (
    "softbench: warning: agent 'broken' of entry point "
    "'hold_still_plugin:NOT_AN_ENTRY' left out: it names a int, not a softbench.agents.AgentEntry"
  )
  assert result.stderr.splitlines().count(warning) == 1, result.stderr
  # In this process: the listing has the good one, and the broken one is refused with why.
  monkeypatch.syspath_prepend(str(tmp_path))
  monkeypatch.setattr(agents, "LEFT_OUT", {})
  monkeypatch.setattr(agents, "_INSTALLED", {})
  assert agents.register_installed() == ["hold-still"]
  with pytest.warns(RuntimeWarning, match="agent 'broken' of entry point"):
    assert cli.main(["agents"]) == 0
  listed = capsys.readouterr().out
  assert "hold-still" in listed and "broken" not in listed
  with pytest.warns(RuntimeWarning, match="agent 'broken' of entry point"):
    assert cli.main([*run[:4], "broken", *run[5:]]) == cli.EXIT_USAGE
  refusal = capsys.readouterr().err.splitlines()
  assert refusal[-1] == "softbench: error: " + warning.removeprefix("softbench: warning: ")
