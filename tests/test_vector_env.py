"""``SoftArmVectorEnv`` (``softbench.envs.vector``): a task on many arms at once, against
Gymnasium's own ``SyncVectorEnv`` of ``SoftArmEnv``s (the serial path): the same observations,
rewards, ends and infos bit for bit, autoresets included, on every task with one robot of each
family (as ``test_envs``), each pair under one of the three autoreset modes in turn.
"""

import example_task
import gymnasium
from gymnasium.utils import env_checker
from gymnasium.vector import AutoresetMode
import numpy as np
import pytest

from softbench import robots
from softbench import suite
import softbench.envs
from softbench.envs import vector
from softbench.robots import faults
from softbench.robots import versions

pytestmark = pytest.mark.skipif(
  versions.current().name == versions.FIRST, reason="SoftArmVectorEnv needs MuJoCo 4's batch"
)

ARMS = 3
EPISODE_STEPS = 1  # One-step episodes, so that every arm's episode ends and autoresets.
STEPS = 3  # Steps of each comparison: an episode, an autoreset (NEXT_STEP) and another.
FAMILY_ROBOTS = sorted({family.example for family in robots.FAMILIES})
MODES = tuple(AutoresetMode)
PAIRS = tuple(
  (robot, task, MODES[index % len(MODES)])
  for index, (robot, task) in enumerate(
    (robot, task) for robot, task in suite.ALL_TASKS if robot in FAMILY_ROBOTS
  )
)


@pytest.fixture(autouse=True)
def shared_cache(tmp_path_factory, monkeypatch):
  """One temporary data home for the whole file, so references are simulated once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "softbench_home"))


def make_pair(robot: str, task: str, mode: AutoresetMode, **options):
  """The vector environment and its serial counterpart, with the same options."""
  options = {**suite.length_options(task, EPISODE_STEPS), **options}
  env_id = softbench.envs.env_id(robot, task)
  batched = gymnasium.make_vec(env_id, ARMS, autoreset_mode=mode, backend="cpu", **options)
  serial = gymnasium.make_vec(
    env_id, ARMS, vectorization_mode="sync", vector_kwargs={"autoreset_mode": mode}, **options
  )
  return batched, serial


def reset_masked(env, mode: AutoresetMode, ended: np.ndarray):
  """Resets the arms whose episodes ended, as a DISABLED-mode caller must."""
  if mode == AutoresetMode.DISABLED and np.any(ended):
    return env.reset(options={"reset_mask": ended.copy()})
  return None


@pytest.mark.parametrize("robot,task,mode", PAIRS)
def test_the_vector_environment_steps_as_gymnasiums_sync_vector_of_softarmenvs(robot, task, mode):
  batched, serial = make_pair(robot, task, mode, observation="dict" if task == "reach" else "flat")
  assert isinstance(batched.unwrapped, vector.SoftArmVectorEnv)
  assert batched.metadata["autoreset_mode"] == mode
  assert env_checker.data_equivalence(batched.reset(seed=7), serial.reset(seed=7), exact=True)
  draw = np.random.default_rng(0)
  for step in range(STEPS):
    action = draw.uniform(-1.0, 1.0, batched.action_space.shape).astype(np.float32)
    got, expected = batched.step(action), serial.step(action)
    assert env_checker.data_equivalence(got, expected, exact=True), (robot, task, mode, step)
    assert batched.observation_space.contains(got[0])
    ended = np.logical_or(got[2], got[3])
    masked = reset_masked(batched, mode, ended), reset_masked(serial, mode, ended)
    assert env_checker.data_equivalence(*masked, exact=True)
  batched.close()
  serial.close()


@pytest.mark.parametrize("robot", robots.LEADERBOARD_ROBOTS)
def test_the_benchmark_robots_vector_environments_pass_gymnasium_s_checks(robot):
  """Each sub-environment's spaces pass Gymnasium's space checks, and the same seed gives the same
  episode (``env_checker``'s determinism rule, on the batched output)."""
  env = gymnasium.make_vec(softbench.envs.env_id(robot, "spiral"), 2, length=EPISODE_STEPS)
  env_checker.check_space_limit(env.single_observation_space, "observation")
  env_checker.check_space_limit(env.single_action_space, "action")
  first, again = env.reset(seed=3), env.reset(seed=3)
  assert env_checker.data_equivalence(first, again, exact=True)
  assert env.observation_space.contains(first[0])
  env.close()


@pytest.mark.parametrize(
  "make_env, message",
  [
    (lambda: vector.SoftArmVectorEnv(0, "tendon-1", "circle"), "positive integer"),
    (lambda: vector.SoftArmVectorEnv(2, "tendon-1", "circle", autoreset_mode="x"), "autoreset"),
    (lambda: vector.SoftArmVectorEnv(2, "tendon-1", "circle", backend="jax"), "backend"),
    (lambda: vector.SoftArmVectorEnv(2, "tendon-1", "circles"), "circles"),
  ],
)
def test_bad_arguments_get_one_line_errors(make_env, message):
  with pytest.raises(ValueError, match=message) as error:
    make_env()
  assert "\n" not in str(error.value)


def test_bad_steps_and_resets_get_clear_errors():
  env = vector.SoftArmVectorEnv(2, "tendon-1", "circle", length=EPISODE_STEPS)
  with pytest.raises(RuntimeError, match="reset"):
    env.step(np.zeros((2, 2)))
  env.reset(seed=0)
  with pytest.raises(ValueError, match="shape"):
    env.step(np.zeros((3, 2)))
  before = env.tasks[0].observation_from(env.batch.poses([0])[0])
  with pytest.raises(ValueError, match="lie in"):
    env.step(np.full((2, 2), 3.0))
  after = env.tasks[0].observation_from(env.batch.poses([0])[0])
  assert env_checker.data_equivalence(before, after, exact=True)  # A refused step changes nothing.
  with pytest.raises(ValueError, match="reset_mask"):
    env.reset(options={"reset_mask": [True, False]})
  with pytest.raises(ValueError, match="seeds"):
    env.reset(seed=[1, 2, 3])


def test_a_faulty_arm_through_the_generic_id_steps_as_its_serial_counterpart():
  """``softbench/SoftArm-vN`` with a robot spec: the fault is in every arm's physics, not in the
  targets (as ``suite.load`` has it)."""
  arm = robots.make("tendon-1").with_faults([faults.Fault(module=1, actuator=0, gain=0.0)])
  options = {"robot": arm, "task": "circle", "length": EPISODE_STEPS}
  batched = gymnasium.make_vec(softbench.envs.ANY_ROBOT_ID, 2, backend="cpu", **options)
  serial = gymnasium.make_vec(softbench.envs.ANY_ROBOT_ID, 2, vectorization_mode="sync", **options)
  assert env_checker.data_equivalence(batched.reset(seed=1), serial.reset(seed=1), exact=True)
  action = np.full(batched.action_space.shape, 0.8, np.float32)
  assert env_checker.data_equivalence(batched.step(action), serial.step(action), exact=True)


class _HoldNearby(example_task.Hold):
  """Hold, with a reward of its own (1 within 1 cm of the start, else 0), which a batch must ask
  arm by arm."""

  def reward_from(self, poses: np.ndarray) -> float:
    return float(np.linalg.norm(poses[:, :3] - self._start[:, :3], axis=-1).max() < 0.01)


@pytest.mark.parametrize("build", [example_task.Hold, _HoldNearby], ids=["hold", "own-reward"])
def test_a_users_task_runs_in_the_batch_as_in_sync_vectorization(build, restored_tasks):
  """A task registered from outside softbench (``example_task.Hold``: its targets come from the
  start's poses, ``episode_started``), also with its own reward."""
  suite.register(
    "hold",
    suite.TaskEntry(
      build=build, tags=(), description="", paper_robot="tendon-1", length_option="steps"
    ),
  )
  options = {"robot": "tendon-1", "task": "hold", "steps": 1}
  batched = gymnasium.make_vec(softbench.envs.ANY_ROBOT_ID, 2, backend="cpu", **options)
  serial = gymnasium.make_vec(softbench.envs.ANY_ROBOT_ID, 2, vectorization_mode="sync", **options)
  assert env_checker.data_equivalence(batched.reset(seed=2), serial.reset(seed=2), exact=True)
  for action in (np.zeros((2, 2), np.float32), np.full((2, 2), 0.3, np.float32)):
    assert env_checker.data_equivalence(batched.step(action), serial.step(action), exact=True)
