"""Properties of the registered Gymnasium environments (``softbench.envs``), and their errors.

Every (robot, task) pair is registered (checked below). The wrapper's properties are checked on
every task with one robot of each family (``FAMILY_ROBOTS``): within a family robots differ only
in their number of modules, and the suite's own tests (``test_suite``) run every task
on every robot. Episodes are shortened as in ``test_suite`` (the properties do not depend on their
length).
"""

import subprocess
import sys
import warnings

import gymnasium
from gymnasium.utils import env_checker
import numpy as np
import pytest

from softbench import agents
from softbench import metrics
from softbench import robots
from softbench import suite
import softbench.envs
from softbench.envs import environment
from softbench.envs import scoring
from softbench.robots import faults
from softbench.robots import versions
from softbench.runners import evaluation
from softbench.suite import references

ID_VERSION = f"v{softbench.envs.VERSION}"  # The installed physics version, which ids end in.

SHORT_STEPS = 3  # Control steps of every shortened episode (as in test_suite: shared references).


def short(task: str) -> dict:
  return suite.length_options(task, SHORT_STEPS)


FAMILY_ROBOTS = {family.example for family in robots.FAMILIES}
FAMILY_PAIRS = tuple((robot, task) for robot, task in suite.ALL_TASKS if robot in FAMILY_ROBOTS)


@pytest.fixture(autouse=True)
def shared_cache(tmp_path_factory, monkeypatch):
  """One temporary data home for the whole file, so references are simulated once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "softbench_home"))


def make(robot, task, **options):
  return gymnasium.make(softbench.envs.env_id(robot, task), **{**short(task), **options})


def test_every_pair_of_the_suite_is_registered_under_its_id():
  ids = set(softbench.envs.env_ids())
  assert {softbench.envs.env_id(robot, task) for robot, task in suite.ALL_TASKS} <= ids
  assert len(ids) == len(robots.REGISTERED_ROBOTS) * len(suite.TASKS)
  assert all(gymnasium.spec(env_id).entry_point == softbench.envs.ENTRY_POINT for env_id in ids)


@pytest.mark.parametrize("robot,task", FAMILY_PAIRS)
def test_gymnasium_checker_passes_without_warnings(robot, task):
  # No random start: the checker resets a dozen times, and the start's randomness is the
  # seeding tests' subject below.
  env = make(robot, task, initial_actuation=0.0)
  with warnings.catch_warnings():
    warnings.simplefilter("error")
    env_checker.check_env(env.unwrapped, skip_render_check=True)
  env.close()


@pytest.mark.parametrize("robot,task", FAMILY_PAIRS)
def test_a_seed_starts_the_episode_the_suite_starts_with_that_seed(robot, task):
  env = make(robot, task)
  suite_env = suite.load(robot, task, seed=7, **short(task))
  action = np.linspace(-0.6, 0.6, env.action_space.shape[0], dtype=np.float32)
  observation, _ = env.reset(seed=7)
  first = suite_env.reset()
  layout = env.unwrapped.observation_layout
  for key, part in layout.items():
    np.testing.assert_array_equal(observation[part], first.observation[key].ravel())
  observation, reward, terminated, truncated, _ = env.step(action)
  after = suite_env.step(action.astype(np.float64))
  np.testing.assert_array_equal(observation[layout["poses"]], after.observation["poses"].ravel())
  assert reward == after.reward and not terminated and not truncated
  again, _ = env.reset(seed=7)  # The same seed again, on the same environment.
  np.testing.assert_array_equal(again, make(robot, task).reset(seed=7)[0])
  other, _ = env.reset(seed=8)
  assert not np.array_equal(other[layout["previous_action"]], again[layout["previous_action"]])


@pytest.mark.parametrize("robot,task", FAMILY_PAIRS)
def test_info_and_score_policy_score_as_the_leaderboard_does(robot, task):
  # A run's episode (evaluation.run_episode, scored by metrics.score), replayed through the
  # Gymnasium environment: info's errors and score_policy's figures are the run's.
  agent = agents.make("random", robot, seed=0)
  run = evaluation.run_episode(suite.load(robot, task, seed=0, **short(task)), agent, task)
  expected = metrics.score(run.achieved, run.targets, robots.make(robot).length)
  replayed = list(run.actions)  # score_policy's seed 0 is the run's seed 0.
  infos = []
  env = make(robot, task)
  env.reset(seed=0)
  for action in run.actions:
    infos.append(env.step(action)[-1])
  assert infos[-1]["scored_modules"] == tuple(run.scored_modules)
  for step, info in enumerate(infos):
    np.testing.assert_array_equal(
      info["position_error_mm"], metrics.position_error_mm(run.achieved[step], run.targets[step])
    )
  assert ("orientation_error_deg" in infos[0]) == bool(expected.orientation_deg)
  score = scoring.score_policy(lambda observation: replayed.pop(0), robot, task, 1, **short(task))
  pairs = [
    ("position_mm", "position_error_mm"),
    ("normalised_tip_percent", "normalised_tip_error_percent"),
  ]
  pairs += [("orientation_deg", "orientation_error_deg")] if expected.orientation_deg else []
  for metric, name in pairs:
    assert score.of(name).mean == pytest.approx(expected.average(metric).mean, rel=1e-12)
  assert str(score).startswith(f"{task} on {robot}: position error ")


def test_score_policy_refuses_a_bad_seed_count():
  with pytest.raises(ValueError, match="seeds must be a positive integer, got 0"):
    scoring.score_policy(lambda observation: None, "tendon-1", "circle", seeds=0)
  with pytest.raises(ValueError, match="seeds must be at most 1,000, got 1001"):
    scoring.score_policy(lambda observation: None, "tendon-1", "circle", seeds=1001)


@pytest.mark.parametrize("robot", sorted(FAMILY_ROBOTS))
def test_two_async_environments_step_in_subprocesses(robot, task="reach"):
  """One task per family: what runs in the subprocesses is SoftArmEnv, whose every task the
  other tests step (the vector environment's own tests compare it with Gymnasium's sync one)."""
  env_id = softbench.envs.env_id(robot, task)
  vector = gymnasium.make_vec(
    env_id, num_envs=2, vectorization_mode="async", **{**short(task), "initial_actuation": 0.0}
  )
  try:
    observations, _ = vector.reset(seed=3)
    assert observations.shape == (2, *vector.single_observation_space.shape)
    actions = np.stack(
      [
        np.full(vector.single_action_space.shape, 0.5, np.float32),
        np.full(vector.single_action_space.shape, -0.5, np.float32),
      ]
    )
    stepped, rewards, terminated, truncated, _ = vector.step(actions)
    assert stepped.shape == observations.shape and np.all(np.isfinite(stepped))
    assert np.all((rewards >= 0) & (rewards <= 1)) and not terminated.any()
    layout = gymnasium.make(env_id, **short(task)).unwrapped.observation_layout
    assert not np.array_equal(stepped[0, layout["poses"]], stepped[1, layout["poses"]])
  finally:
    vector.close()


@pytest.mark.parametrize("task", suite.TASKS[:1] + ("reach",))
def test_an_episode_ends_truncated_when_its_reference_runs_out(task):
  env = make("tendon-1", task)
  env.reset(seed=0)
  steps = env.unwrapped.dm_env.task.num_steps
  ends = [env.step(env.action_space.sample())[2:4] for _ in range(steps)]
  assert ends[:-1] == [(False, False)] * (len(ends) - 1) and ends[-1] == (False, True)
  with pytest.raises(RuntimeError, match="call reset"):
    env.unwrapped.step(env.action_space.sample())


def test_the_dict_form_holds_the_flat_form_s_parts():
  flat = make("pneumatic-433", "reach")
  named = make("pneumatic-433", "reach", observation="dict")
  vector, _ = flat.reset(seed=2)
  parts, _ = named.reset(seed=2)
  assert named.observation_space.contains(parts)
  for key, part in flat.unwrapped.observation_layout.items():
    np.testing.assert_array_equal(vector[part], parts[key].ravel())
  assert parts["target"].shape == (1, 3)  # Reach asks for one module's position.


def test_custom_follows_the_trajectory_given_to_make():
  arm = robots.make("tendon-2")
  targets = references.reference(arm, "circle", 3).targets
  env = gymnasium.make(softbench.envs.env_id("tendon-2", "custom"), trajectory=targets)
  observation, _ = env.reset(seed=0)
  np.testing.assert_array_equal(
    observation[env.unwrapped.observation_layout["target"]], targets[0].ravel()
  )


def test_any_robot_and_fault_through_the_generic_id():
  env = gymnasium.make(softbench.envs.ANY_ROBOT_ID, robot="tendon-7", task="reach", steps=1)
  observation, _ = env.reset(seed=0)
  assert observation.shape == (7 * 6 + 3 + robots.make("tendon-7").action_dim,)
  healthy = robots.make("tendon-2")
  punctured = healthy.with_faults([faults.Fault(module=2, actuator=0, gain=0.0)])
  tips = []
  for arm in (healthy, punctured):
    env = gymnasium.make(softbench.envs.ANY_ROBOT_ID, robot=arm, task="reach", steps=1)
    env.reset(seed=0)
    observation = env.step(np.ones(arm.action_dim, np.float32))[0]
    tips.append(observation[env.unwrapped.observation_layout["poses"]][6:9])
  assert np.linalg.norm(tips[0] - tips[1]) > 1e-3  # (m) The fault changes the physics.


@pytest.mark.parametrize("robot", robots.REGISTERED_ROBOTS)
def test_rgb_array_frames_show_the_arm_headlessly(robot):
  env = make(robot, "reach", render_mode="rgb_array", width=96, height=64)
  env.reset(seed=0)
  first = env.render()
  env.step(np.ones(env.action_space.shape, np.float32))
  moved = env.render()
  assert first.shape == (64, 96, 3) and first.dtype == np.uint8
  assert first.std() > 0 and not np.array_equal(first, moved)
  env.close()


@pytest.mark.parametrize(
  "make_env,message",
  [
    (
      lambda: gymnasium.make(f"softbench/tendon-3-spiral-{ID_VERSION}", lenght=3),
      "no option 'lenght'",
    ),
    (lambda: gymnasium.make(f"softbench/tendon-3-custom-{ID_VERSION}"), "needs a trajectory"),
    (
      lambda: gymnasium.make(f"softbench/tendon-3-reach-{ID_VERSION}", module=4),
      "module must be 1 to 3",
    ),
    (
      lambda: gymnasium.make(f"softbench/tendon-3-reach-{ID_VERSION}", observation="image"),
      "observation must be one of flat, dict",
    ),
    (
      lambda: environment.SoftArmEnv("tendon-3", "reach", render_mode="ansi"),
      "render_mode must be None or one of rgb_array",
    ),
    (
      lambda: gymnasium.make(f"softbench/tendon-3-reach-{ID_VERSION}", width=64),
      "need render_mode",
    ),
    (
      lambda: gymnasium.make(
        f"softbench/tendon-3-reach-{ID_VERSION}", render_mode="rgb_array", width=7
      ),
      "width must be an even number",
    ),
    (
      lambda: gymnasium.make(softbench.envs.ANY_ROBOT_ID, robot="tendon-03", task="reach"),
      "tendon-03",
    ),
    (
      lambda: gymnasium.make(softbench.envs.ANY_ROBOT_ID, robot="tendon-3", task="wave"),
      "unknown task 'wave'",
    ),
  ],
)
def test_bad_options_get_one_line_errors(make_env, message):
  with pytest.raises(ValueError, match=message) as error:
    make_env()
  assert "\n" not in str(error.value)


@pytest.mark.parametrize("seed", [-1, 2**32, 1.5])
def test_bad_seeds_and_reset_options_get_one_line_errors(seed):
  env = make("tendon-1", "reach")
  with pytest.raises(ValueError, match="seed") as error:
    env.reset(seed=seed)
  assert "\n" not in str(error.value)
  with pytest.raises(ValueError, match="reset takes no options"):
    env.reset(options={"length": 2})


def test_render_before_reset_and_step_before_reset_are_clear_errors():
  env = environment.SoftArmEnv("tendon-1", "reach", render_mode="rgb_array", width=32, height=32)
  with pytest.raises(RuntimeError, match="reset"):
    env.render()
  with pytest.raises(RuntimeError, match="reset"):
    env.step(np.zeros(4, np.float32))


def test_the_physics_side_and_the_environments_import_without_torch():
  code = (
    "import sys, softbench.suite, softbench.robots, softbench.rendering.video, "
    "softbench.rendering.live, softbench.envs; print('torch' in sys.modules)"
  )
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  assert result.stdout.strip() == "False"


def test_a_make_without_importing_softbench_uses_the_module_form():
  code = (
    "import gymnasium; env = gymnasium.make("
    f"'softbench.envs:softbench/tendon-1-reach-{ID_VERSION}', steps=1); "
    "print(env.reset(seed=0)[0].shape)"
  )
  result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
  assert result.stdout.strip() == "(11,)"  # tendon-1: one pose (6), the point (3), 2 cables.


def test_ids_end_in_the_installed_physics_version():
  assert ID_VERSION == versions.current().name
  assert all(env_id.endswith(f"-{ID_VERSION}") for env_id in softbench.envs.env_ids())
  other = next(name for name in versions.VERSIONS if name != ID_VERSION)
  with pytest.raises(gymnasium.error.Error, match=ID_VERSION):  # Gymnasium names the one there is.
    gymnasium.make(f"softbench/tendon-3-spiral-{other}")
