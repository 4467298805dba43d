"""Properties of every task on every registered robot, in the style of dm_control's suite_test.

Episodes are shortened (``length``/``steps``) so that the whole file runs in well under a minute;
the properties do not depend on the length.
"""

import json
import re
import warnings

from dm_env import specs
import example_task
import numpy as np
import pytest

from softbench import agents
from softbench import cli
from softbench import data
from softbench import robots
from softbench import storage
from softbench import suite
from softbench import terminal
from softbench.robots import recorder
from softbench.suite import references
from softbench.suite import registry

SHORT_STEPS = 3  # Control steps of every shortened episode; short_env gives `custom` 3 targets.
# Every task on every registered robot: ALL_TASKS, plus the user's `custom` task.
EVERY_TASK = tuple((robot, task) for robot in robots.REGISTERED_ROBOTS for task in suite.TASKS)
FAMILY_EXAMPLES = {family.example for family in robots.FAMILIES}


@pytest.fixture(autouse=True)
def shared_cache(tmp_path_factory, monkeypatch):
  """One temporary data home for the whole file, so references are simulated once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "softbench_home"))


def short_env(robot, task, seed=0, **options):
  if task == "custom":
    options = {
      "trajectory": references.reference(robots.make(robot), "circle", 3).targets,
      **options,
    }
  return suite.load(
    robot, task, seed=seed, **{**suite.length_options(task, SHORT_STEPS), **options}
  )


def random_actions(env, seed=0):
  rng = np.random.default_rng(seed)
  spec = env.action_spec()
  while True:
    yield rng.uniform(spec.minimum, spec.maximum, spec.shape)


def run_episode(env, seed=0):
  """The observations and rewards of one episode under random actions."""
  time_step = env.reset()
  observations, rewards = [time_step.observation], []
  for action in random_actions(env, seed):
    time_step = env.step(action)
    observations.append(time_step.observation)
    rewards.append(time_step.reward)
    if time_step.last():
      return observations, rewards


@pytest.mark.parametrize("robot,task", EVERY_TASK)
class TestEveryTask:
  def test_observations_match_specs_and_rewards_lie_in_unit_interval(self, robot, task):
    env = short_env(robot, task, seed=3)
    observation_spec = env.observation_spec()
    observations, rewards = run_episode(env, seed=5)
    for observation in observations:
      assert set(observation) == {"poses", "target", "previous_action"}
      for name, value in observation.items():
        observation_spec[name].validate(value)
        assert np.all(np.isfinite(value)), name
    assert len(rewards) == env.task.num_steps
    assert all(0.0 <= reward <= 1.0 for reward in rewards)

  def test_actions_are_bounded_to_unit_box(self, robot, task):
    spec = short_env(robot, task).action_spec()
    assert isinstance(spec, specs.BoundedArray)
    assert spec.shape == (robots.make(robot).action_dim,)
    np.testing.assert_array_equal(spec.minimum, -1.0)
    np.testing.assert_array_equal(spec.maximum, 1.0)

  def test_resets_differ_across_seeds(self, robot, task):
    first = short_env(robot, task, seed=1).reset().observation
    second = short_env(robot, task, seed=2).reset().observation
    assert not np.array_equal(first["poses"], second["poses"])

  def test_rejects_nan_and_out_of_range_actions(self, robot, task):
    env = short_env(robot, task)
    env.reset()
    action = np.zeros(env.action_spec().shape)
    with pytest.raises(ValueError, match="NaN"):
      env.step(np.full_like(action, np.nan))
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
      env.step(action + 1.5)


# Within a family robots differ only in their module count; one robot of each shows a repeat.
@pytest.mark.parametrize("robot,task", [pair for pair in EVERY_TASK if pair[0] in FAMILY_EXAMPLES])
def test_the_same_seeds_on_a_new_environment_repeat_the_episode(robot, task):
  observations, rewards = run_episode(short_env(robot, task, seed=3), seed=5)
  again, again_rewards = run_episode(short_env(robot, task, seed=3), seed=5)
  assert again_rewards == rewards
  for first, second in zip(observations, again):
    for name in first:
      np.testing.assert_array_equal(first[name], second[name])


SHAPES = tuple(task for task in suite.TASKS if suite.describe(task).reference)  # Of references.


@pytest.mark.parametrize("robot", robots.REGISTERED_ROBOTS)
@pytest.mark.parametrize("shape", SHAPES)
def test_every_reference_is_reachable(robot, shape):
  """Replaying a reference's generating actions from rest reproduces its poses exactly."""
  reference = references.reference(robots.make(robot), shape, length=4)
  env = suite.load(robot, shape, length=4, initial_actuation=0.0)
  env.reset()
  achieved = []
  for action in reference.actions:
    achieved.append(env.step(action).observation["poses"])
    assert env.physics.data.warning.number.sum() == 0
  np.testing.assert_allclose(np.array(achieved), reference.targets, rtol=0, atol=1e-12)


@pytest.mark.parametrize("robot", robots.REGISTERED_ROBOTS)
def test_bend_amplitude_bends_the_end_effector_by_the_stated_angle(robot):
  arm = robots.make(robot)
  amplitude = references.bend_amplitude(arm)
  holds = int(np.ceil(references.SETTLE_SECONDS / arm.control_timestep))
  action = arm.planar_action(np.array([amplitude, 0.0]))
  poses, _ = recorder.PoseRecorder(arm).record(np.tile(action, (1, holds, 1)))
  axis, rest_axis = poses[0, -1, -1, 3:], poses[0, 0, -1, 3:]
  bend = np.degrees(np.arccos(np.clip(axis @ rest_axis, -1, 1)))
  assert abs(bend - references.BEND_DEG) < 3.0


@pytest.mark.parametrize("cores", [1, 3])
def test_bend_amplitude_stops_early_at_the_answer_of_the_whole_grid(cores, monkeypatch):
  arm = robots.make("tendon-2")  # Reaches BEND_DEG at the 7th of 20 grid points.
  calibrate = references.bend_amplitude.__wrapped__  # Past the cache.
  monkeypatch.setattr(references.os, "cpu_count", lambda: len(references.AMPLITUDE_GRID))
  whole_grid = calibrate(arm)  # One batch: every actuation held.
  monkeypatch.setattr(references.os, "cpu_count", lambda: cores)
  assert calibrate(arm) == whole_grid


def test_reference_shapes_differ_and_stay_in_unit_actuation():
  arm = robots.make("pneumatic-433")
  actions = {shape: references.pattern_actions(arm, shape, 50, amplitude=0.5) for shape in SHAPES}
  for shape, action in actions.items():
    assert action.shape == (50, arm.action_dim)
    assert np.all(np.abs(action) <= 1.0), shape
  for shape in ("circle", "rectangle", "spiral"):
    assert not np.array_equal(actions[shape], actions["babbling"])
  # The spiral grows outward: later actuation is larger than early actuation.
  magnitude = np.linalg.norm(actions["spiral"], axis=1)
  assert magnitude[:10].mean() < magnitude[-10:].mean()


def test_a_recording_from_rest_is_simulated_once_per_robot_and_actions(monkeypatch):
  arm = robots.make("tendon-1")
  actions = np.random.default_rng(0).uniform(-1.0, 1.0, (3, arm.action_dim))
  recorded, _ = recorder.PoseRecorder(arm).record(actions[None])
  first = recorder.from_rest(arm, actions)
  np.testing.assert_array_equal(first, recorded[0])
  assert not first.flags.writeable

  def simulated(*args, **kwargs):
    raise AssertionError("simulated")

  with monkeypatch.context() as patch:
    patch.setattr(recorder.PoseRecorder, "record", simulated)
    assert recorder.from_rest(robots.make("tendon-1"), actions.copy()) is first  # Equal inputs.
    for other_robot, other_actions in [(arm, actions[:2]), (arm.refined(2), actions)]:
      with pytest.raises(AssertionError, match="simulated"):
        recorder.from_rest(other_robot, other_actions)


def test_reference_is_cached_and_a_corrupt_cache_is_regenerated(monkeypatch, tmp_path):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  arm = robots.make("tendon-1")
  first = references.reference(arm, "circle", length=5)
  (npz,) = (tmp_path / "references").glob("*.npz")

  def must_not_simulate(*args, **kwargs):
    raise AssertionError("a cached reference was simulated again")

  with monkeypatch.context() as patch:
    patch.setattr(recorder.PoseRecorder, "record", must_not_simulate)
    cached = references.reference(arm, "circle", length=5)
  np.testing.assert_array_equal(cached.poses, first.poses)

  data = bytearray(npz.read_bytes())
  data[len(data) // 2] ^= 0xFF
  npz.write_bytes(bytes(data))
  unreadable = re.escape(f"{npz}: unreadable cached reference")
  with pytest.warns(storage.CorruptFileWarning, match=unreadable):
    regenerated = references.reference(arm, "circle", length=5)
  np.testing.assert_array_equal(regenerated.poses, first.poses)
  meta = json.loads(npz.with_suffix(".json").read_text())
  assert meta["config"]["shape"] == "circle"


def test_simulating_a_reference_says_so_once(monkeypatch, tmp_path, capsys):
  # The first suite.load of a (robot, task) waits 7 to 132 s for its reference: never silently.
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  arm = robots.make("tendon-1")
  simulated = references.reference(arm, "spiral", length=6)
  line = (
    "simulating tendon-1's spiral reference (6 control steps; once, then cached in the data home)"
  )
  assert capsys.readouterr().err.splitlines() == [line]
  np.testing.assert_array_equal(simulated.poses, recorder.from_rest(arm, simulated.actions))
  references.reference(arm, "spiral", length=6)
  assert capsys.readouterr().err == ""


@pytest.mark.parametrize(
  "description", ["[]", "null", '"text"', '{"config": 1}', "{", "", "[" * 100_000]
)
def test_a_malformed_cached_reference_description_is_regenerated(
  description, monkeypatch, tmp_path
):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  arm = robots.make("tendon-1")
  first = references.reference(arm, "circle", length=4)
  (meta,) = (tmp_path / "references").glob("*.json")
  meta.write_text(description)
  with pytest.warns(storage.CorruptFileWarning, match="unreadable cached reference"):
    regenerated = references.reference(arm, "circle", length=4)
  np.testing.assert_array_equal(regenerated.poses, first.poses)
  assert json.loads(meta.read_text())["config"]["shape"] == "circle"
  with warnings.catch_warnings():
    warnings.simplefilter("error")
    references.reference(arm, "circle", length=4)  # Cached again, intact.


def test_a_damaged_reference_warns_on_one_softbench_line(monkeypatch, tmp_path):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  arm = robots.make("tendon-1")
  references.reference(arm, "circle", length=4)
  (meta,) = (tmp_path / "references").glob("*.json")
  meta.write_text("null")
  with pytest.warns(storage.CorruptFileWarning) as caught:
    references.reference(arm, "circle", length=4)
  monkeypatch.setattr(warnings, "formatwarning", warnings.formatwarning)
  terminal.one_line_warnings()  # As the command line prints warnings.
  (warning,) = caught
  printed = warnings.formatwarning(
    warning.message, warning.category, warning.filename, warning.lineno
  )
  assert printed.startswith(
    f"softbench: warning: {meta.with_suffix('.npz')}: unreadable cached reference ("
  )
  assert printed.count("\n") == 1 and printed.endswith("; generating it again\n")


def test_reach_targets_are_reachable_points_that_vary_with_seed():
  arm = robots.make("tendon-3")
  targets = []
  for seed in (0, 1):
    env = suite.load(arm, "reach", seed=seed, steps=1)
    observation = env.reset().observation
    assert observation["target"].shape == (1, 3)
    targets.append(observation["target"][0])
    assert np.linalg.norm(targets[-1]) <= arm.length
  assert not np.allclose(targets[0], targets[1])
  assert suite.load(arm, "reach", steps=1).task.scored_modules() == (2,)


def test_reward_is_one_on_target_and_falls_with_distance():
  arm = robots.make("tendon-2")
  rest = recorder.PoseRecorder(arm).poses(recorder.PoseRecorder(arm).rest_state())
  shifted = rest.copy()
  shifted[:, 0] += 0.05 * arm.length  # 5 % of the arm length away along x.
  env = suite.load(arm, "custom", trajectory=np.stack([rest, shifted]), initial_actuation=0.0)
  env.reset()
  zero = np.zeros(arm.action_dim)
  assert env.step(zero).reward == pytest.approx(1.0)
  assert 0.1 < env.step(zero).reward < 1.0


class TestCustomTrajectory:
  @pytest.fixture
  def rows(self):
    arm = robots.make("tendon-2")
    rest = recorder.PoseRecorder(arm).poses(recorder.PoseRecorder(arm).rest_state())
    return np.tile(rest.reshape(1, -1), (4, 1))

  @pytest.mark.parametrize("suffix", [".npy", ".csv"])
  def test_file_gives_the_same_targets_as_the_array(self, rows, tmp_path, suffix):
    path = tmp_path / f"trajectory{suffix}"
    if suffix == ".npy":
      np.save(path, rows)
    else:
      np.savetxt(path, rows, delimiter=",", header="x1,y1,z1,u1,v1,w1,x2,y2,z2,u2,v2,w2")
    from_file = suite.load("tendon-2", "custom", trajectory=path).reset().observation["target"]
    from_array = suite.load("tendon-2", "custom", trajectory=rows).reset().observation["target"]
    np.testing.assert_allclose(from_file, from_array, atol=1e-15)
    assert suite.load("tendon-2", "custom", trajectory=path).task.num_steps == 4

  @pytest.mark.parametrize(
    "change,message",
    [
      (lambda rows: rows[:, :6], r"\(steps, 12\)"),
      (lambda rows: rows[0], r"\(steps, 12\)"),
      (lambda rows: rows[:0], "no rows"),
      (lambda rows: np.where(np.arange(12) == 2, np.nan, rows), "NaN"),
      (lambda rows: rows * 2, "unit length"),
      (lambda rows: np.where(np.arange(12) < 3, 1e300, rows), "arm lengths"),
      (lambda rows: np.where(np.arange(12) == 2, -0.5, rows), "arm lengths"),  # 500 mm, 100 long.
    ],
  )
  def test_malformed_trajectory_gets_a_clear_error(self, rows, change, message):
    with pytest.raises(ValueError, match=message):
      suite.load("tendon-2", "custom", trajectory=change(rows))

  def test_unreadable_files(self, tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
      suite.load("tendon-2", "custom", trajectory=tmp_path / "missing.npy")
    (tmp_path / "bad.csv").write_text("1,2,three\n")
    with pytest.raises(ValueError, match="unreadable"):
      suite.load("tendon-2", "custom", trajectory=tmp_path / "bad.csv")
    (tmp_path / "bad.npy").write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(ValueError, match="unreadable"):
      suite.load("tendon-2", "custom", trajectory=tmp_path / "bad.npy")
    (tmp_path / "trajectory.txt").write_text("0\n")
    with pytest.raises(ValueError, match=".npy or .csv"):
      suite.load("tendon-2", "custom", trajectory=tmp_path / "trajectory.txt")

  def test_missing_trajectory(self):
    with pytest.raises(ValueError, match="needs a trajectory"):
      suite.load("tendon-2", "custom")


@pytest.mark.parametrize(
  "call,message",
  [
    (lambda: suite.load("tendon-3", "juggle"), "unknown task 'juggle'"),
    (lambda: suite.load("octopus-8", "circle"), "unknown robot"),
    (lambda: suite.load("tendon-11", "circle"), "1 to 10 modules"),
    (lambda: suite.load("tendon-3", "circle", speed=2), "no option 'speed'"),
    (lambda: suite.load("tendon-3", "circle", length=0), "positive integer"),
    (lambda: suite.load("tendon-3", "reach", module=4), "module must be 1 to 3"),
    (lambda: suite.load("tendon-3", "reach", steps=0), "positive integer"),
    (lambda: suite.load("tendon-3", "circle", length=2, initial_actuation=2.0), r"\[0, 1\]"),
  ],
)
def test_bad_arguments_get_one_line_errors(call, message):
  with pytest.raises(ValueError, match=message) as error:
    call()
  assert "\n" not in str(error.value)


def test_registry_lists():
  needs_input = [task for task in suite.TASKS if "user" in suite.describe(task).tags]
  assert needs_input == ["custom"]
  assert suite.ALL_TASKS == tuple(
    (robot, task)
    for robot in robots.REGISTERED_ROBOTS
    for task in suite.TASKS
    if task not in needs_input
  )
  assert set(suite.BENCHMARKING) <= set(suite.ALL_TASKS)
  assert ("tendon-3", "spiral") in suite.BENCHMARKING


def test_a_tracking_task_registered_from_outside_runs_on_every_robot(figure_eight):
  # One decorated function (example_task.register_figure_eight) makes a task like the built-in
  # ones: listed, benchmarked, and loaded and run on every registered robot. (Alone, the test
  # first calibrates every robot's bend amplitude, as the file's other tests do: 10 to 30 s.)
  assert suite.TASKS[-1] == figure_eight and ("tendon-3", figure_eight) in suite.BENCHMARKING
  assert suite.describe(figure_eight).tags == ("benchmarking", "tracking")
  assert suite.length_options(figure_eight, SHORT_STEPS) == {"length": SHORT_STEPS}
  for robot in robots.REGISTERED_ROBOTS:
    observations, rewards = run_episode(short_env(robot, figure_eight, seed=1), seed=2)
    assert len(rewards) == SHORT_STEPS and all(0.0 <= reward <= 1.0 for reward in rewards)
    reference = references.reference(robots.make(robot), figure_eight, SHORT_STEPS)  # Cached.
    np.testing.assert_array_equal(observations[0]["target"], reference.targets[0])
    assert reference.actions.shape == (SHORT_STEPS, robots.make(robot).action_dim)


def test_a_shape_s_cached_references_depend_on_its_own_parameters_only(
  restored_tasks, monkeypatch, tmp_path
):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  arm = robots.make("tendon-1")
  circle = references.reference(arm, "circle", length=3)
  twice = example_task.register_figure_eight(laps=2)
  once = references.reference(arm, twice, length=3)
  del registry._TASKS[twice]  # restored_tasks restores the registry after the test.
  thrice = references.reference(arm, example_task.register_figure_eight(laps=3), length=3)
  assert not np.array_equal(once.poses, thrice.poses)
  assert len(list((tmp_path / references.FOLDER).glob("*.npz"))) == 3  # Circle and two eights.

  def must_not_simulate(*args, **kwargs):
    raise AssertionError("a cached reference was simulated again")

  monkeypatch.setattr(recorder.PoseRecorder, "record", must_not_simulate)
  np.testing.assert_array_equal(references.reference(arm, "circle", length=3).poses, circle.poses)


BAD_SEEDS = [2**32, 2**70, -1, "x", 1.5, True]


@pytest.mark.parametrize("seed", BAD_SEEDS, ids=repr)
@pytest.mark.parametrize("entry", ["suite.load", "data.collect", "agents.make"])
def test_one_seed_rule_everywhere(entry, seed, monkeypatch, tmp_path):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  calls = {
    "suite.load": lambda: suite.load("tendon-1", "circle", seed=seed, length=3),
    "data.collect": lambda: data.collect("tendon-1", samples=4, seed=seed, progress=False),
    "agents.make": lambda: agents.make("zero", "tendon-1", seed),
  }
  with pytest.raises(ValueError, match=r"^seed must be an integer from 0 to 4294967295, got "):
    calls[entry]()
  assert not (tmp_path / "datasets").exists()


@pytest.mark.parametrize(
  "command",
  [
    ["collect", "--robot", "tendon-1", "--seed"],
    [
      "render",
      "--task",
      "circle",
      "--agent",
      "zero",
      "--robot",
      "tendon-1",
      "--out",
      "never.mp4",
      "--seed",
    ],
  ],
)
def test_the_cli_takes_seeds_by_the_same_rule(command, capsys, tmp_path, monkeypatch):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path))
  assert cli.main([*command, str(2**70)]) == cli.EXIT_USAGE
  assert capsys.readouterr().err == (
    f"softbench: error: seed must be an integer from 0 to 4294967295, got {2**70}\n"
  )
