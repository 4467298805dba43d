"""The sac agent: its training stream, its input scaling, and a training that resumes to the same
weights (the registry-wide agent tests cover its acting, its records and a damaged checkpoint's
retraining)."""

import tempfile

import numpy as np
import pytest
import stable_baselines3
import torch

from smpl import snapshots
from softbench import data
from softbench import profiles
from softbench import robots
from softbench.agents import base
from softbench.agents import completion
from softbench.agents import sac
from softbench.data import splits
from softbench.envs import environment
from softbench.envs import streams
from softbench.learning import inverse as inverse_training

ROBOT = "tendon-1"
TINY = profiles.get("tiny")
# (bytes) What a saved model or training state holds beyond its SB3 zip and replay buffer (its
# configuration, random states, torch's container); with torch.save's default pickle protocol
# the zip alone grew by about 45 %.
FILE_OVERHEAD_BYTES = 64 * 2**10


EPISODE_STEPS = 5  # Short episodes: two of them per arm in the tiny training below.


def arms() -> int:
  """The arms a training steps at once on the installed physics (1 on v0)."""
  return sac.num_envs(sac.training_config(robots.make(ROBOT), 0, TINY))


@pytest.fixture
def home(tmp_path, monkeypatch, babbled_home):
  babbled_home(tmp_path / "home", ROBOT)
  monkeypatch.setattr(sac, "EPISODE_STEPS", EPISODE_STEPS)
  monkeypatch.setattr(sac, "CHUNK_STEPS", EPISODE_STEPS)  # One episode per arm per chunk,
  monkeypatch.setitem(sac.STEPS, "tiny", 2 * EPISODE_STEPS * arms())  # two chunks in all.
  monkeypatch.setattr(snapshots, "SAVE_INTERVAL_S", 0.0)  # Save after every chunk.
  return tmp_path / "home"


@pytest.fixture
def stream(home) -> list[np.ndarray]:
  """The training stream of 10-step episodes on the tiny dataset of ``ROBOT``."""
  dataset = data.collect(
    ROBOT, samples=TINY.samples, seed=inverse_training.DATA_SEED, progress=False
  )
  return streams.training_targets(dataset, 10)


def _weights(trained: dict) -> dict[str, torch.Tensor]:
  import io  # pylint: disable=import-outside-toplevel

  return stable_baselines3.SAC.load(io.BytesIO(trained["model"])).policy.state_dict()


def test_an_interrupted_training_resumes_to_the_same_weights(
  home, tmp_path, monkeypatch, babbled_home
):
  temporary = tmp_path / "temporary"  # SB3's own logger makes an SB3-* folder here per learn().
  temporary.mkdir()
  monkeypatch.setattr(tempfile, "tempdir", str(temporary))
  arm = robots.make(ROBOT)
  whole = sac.train(arm, 0, TINY)
  assert whole["environment_steps"] == sac.STEPS["tiny"]
  assert whole["episodes"] == 3 * arms()  # Two per arm, and the next one begun.
  babbled_home(tmp_path / "other", ROBOT)
  learn, calls = stable_baselines3.SAC.learn, []

  def interrupted_in_the_second_chunk(model, *args, **kwargs):
    calls.append(model.num_timesteps)
    if len(calls) == 2:
      raise KeyboardInterrupt
    return learn(model, *args, **kwargs)

  with monkeypatch.context() as patched:
    patched.setattr(stable_baselines3.SAC, "learn", interrupted_in_the_second_chunk)
    with pytest.raises(KeyboardInterrupt):
      sac.train(arm, 0, TINY)
  # Saved after the first chunk, which learned from its last step.
  assert calls == [0, EPISODE_STEPS * arms()]
  partial = sac.checkpoint_path(arm, 0, TINY).with_suffix(".partial.pt")
  assert partial.is_file() and not sac.checkpoint_path(arm, 0, TINY).exists()
  saved = torch.load(partial, weights_only=False)
  held = len(saved["model"]) + len(saved["replay_buffer"])
  assert partial.stat().st_size < held + FILE_OVERHEAD_BYTES  # Bytes written as they are.
  resumed = sac.train(arm, 0, TINY)
  assert not partial.exists()
  model_file = sac.checkpoint_path(arm, 0, TINY)
  assert model_file.stat().st_size < len(resumed["model"]) + FILE_OVERHEAD_BYTES
  assert resumed["environment_steps"] == whole["environment_steps"]
  first, second = _weights(whole), _weights(resumed)
  assert first.keys() == second.keys()
  for name in first:
    assert torch.equal(first[name], second[name]), name
  assert not list(temporary.glob("SB3-*"))  # Neither training nor resuming left a log folder.


def test_training_episodes_follow_training_stretches_fixed_by_the_seed(home):
  arm = robots.make(ROBOT)
  dataset = data.collect(
    ROBOT, samples=TINY.samples, seed=inverse_training.DATA_SEED, progress=False
  )
  stream = streams.training_targets(dataset, 10)
  env = streams.TargetStreamEnv(arm, stream, 10, seed=4)
  later = streams.TargetStreamEnv(arm, stream, 10, seed=4, first_episode=2)
  train_pieces = splits.split_pieces(dataset.episode_lengths)["train"]
  training_poses = np.concatenate([piece.recording(dataset)[0][1:] for piece in train_pieces])
  windows = []
  for episode in range(3):
    observation, _ = env.reset()
    targets, _ = env.window(episode)
    windows.append(targets)
    np.testing.assert_array_equal(
      observation[
        env.observation_space.shape[0] - arm.action_dim - targets[0].size : -arm.action_dim
      ],
      targets[0].ravel(),
    )
    assert all(np.any(np.all(training_poses == pose, axis=(1, 2))) for pose in targets)
  np.testing.assert_array_equal(later.reset()[0], env.__class__(arm, stream, 10, 4, 2).reset()[0])
  assert not np.array_equal(windows[0], windows[1])
  rewards = [env.step(env.action_space.sample())[1] for _ in range(10)]
  assert all(0 <= reward <= 1 for reward in rewards)


def test_policy_input_scales_positions_only():
  shapes = {"poses": (2, 6), "target": (1, 3), "previous_action": (4,)}
  named = {
    "poses": np.arange(12.0).reshape(2, 6),
    "target": np.array([[1.0, 2.0, 3.0]]),
    "previous_action": np.array([0.5, -0.5, 1.0, 0.0]),
  }
  scaled = sac.policy_input(environment.flatten(named), shapes, length=2.0)
  assert scaled.dtype == np.float32
  np.testing.assert_array_equal(scaled[:12], [0, 0.5, 1, 3, 4, 5, 3, 3.5, 4, 9, 10, 11])
  np.testing.assert_array_equal(scaled[12:15], [0.5, 1.0, 1.5])
  np.testing.assert_array_equal(scaled[15:], named["previous_action"])


@pytest.mark.skipif(arms() == 1, reason="vector training needs MuJoCo 4's batch (physics v1)")
def test_the_arms_of_the_vector_stream_start_the_sequence_s_episodes_in_order(stream):
  arm = robots.make(ROBOT)
  batched = streams.TargetStreamVectorEnv(3, arm, stream, 10, seed=4, first_episode=1)
  serial = streams.TargetStreamEnv(arm, stream, 10, seed=4, first_episode=1)
  observations, _ = batched.reset()
  for observation in observations:
    np.testing.assert_array_equal(observation, serial.reset()[0])
  assert batched.episodes_started == serial.episodes_started == 4


@pytest.mark.parametrize("reward", streams.REWARDS)
def test_a_training_step_rewards_the_task_or_the_distance_to_the_targets(stream, reward):
  arm = robots.make(ROBOT)
  env = streams.TargetStreamEnv(arm, stream, 10, seed=4, reward=reward)
  env.reset()
  task_env = streams.TargetStreamEnv(arm, stream, 10, seed=4)
  task_env.reset()
  for action in np.random.default_rng(0).uniform(-1, 1, (3, arm.action_dim)):
    _, given, _, _, info = env.step(action)
    _, task_reward, _, _, task_info = task_env.step(action)
    error_m = np.mean(task_info["position_error_mm"]) / 1000.0
    assert error_m > 0
    if reward == "task":
      assert given == task_reward
    else:  # Minus the distance in arm lengths, dense where the task's reward is not.
      assert given == pytest.approx(-error_m / arm.length, rel=1e-12)


@pytest.mark.skipif(arms() == 1, reason="vector training needs MuJoCo 4's batch (physics v1)")
def test_the_vector_stream_rewards_each_arm_as_its_serial_stream_does(stream):
  arm = robots.make(ROBOT)
  batched = streams.TargetStreamVectorEnv(
    2, arm, stream, 10, seed=4, reward="distance", backend="cpu"
  )
  serial = [
    streams.TargetStreamEnv(arm, stream, 10, seed=4, first_episode=arm_index, reward="distance")
    for arm_index in range(2)
  ]
  batched.reset()
  for env in serial:
    env.reset()
  for actions in np.random.default_rng(1).uniform(-1, 1, (3, 2, arm.action_dim)):
    rewards = batched.step(actions)[1]
    expected = [env.step(action)[1] for env, action in zip(serial, actions)]
    np.testing.assert_array_equal(rewards, expected)
    assert np.all(rewards < 0)


def test_an_unknown_training_reward_is_one_line(home):
  arm = robots.make(ROBOT)
  stream = [np.zeros((10, 1, 6))]
  with pytest.raises(ValueError, match="^reward must be one of task, distance, got 'sparse'$"):
    streams.TargetStreamEnv(arm, stream, 10, seed=0, reward="sparse")


def test_a_partial_target_is_completed_with_the_nearest_babbling_pose_on_v1_held_on_v0(
  home, monkeypatch
):
  arm = robots.make(ROBOT)
  agent = sac.build(arm, 0, TINY)
  shown = []

  def predict(observation, deterministic):
    shown.append(observation)
    return np.zeros(arm.action_dim, np.float32), None

  monkeypatch.setattr(agent._model, "predict", predict)  # pylint: disable=protected-access
  start = np.array([[0.0, 0.0, arm.length, 0.0, 0.0, 1.0]])
  goal = np.array([[0.3, -0.2, 0.8]]) * arm.length  # Module 1's position only, as reach gives.
  agent.reset(base.EpisodeInfo("reach", (1,)))
  agent.act({"poses": start, "target": goal, "previous_action": np.zeros(arm.action_dim)})
  shapes = {"poses": (1, 6), "target": (1, 6), "previous_action": (arm.action_dim,)}
  target = shown[0][environment.layout(shapes)["target"]]
  np.testing.assert_allclose(target[:3], goal[0] / arm.length, rtol=1e-6)
  if arms() == 1:  # v0: the starting pose's orientation, as its records were made.
    np.testing.assert_allclose(target[3:], start[0, 3:], rtol=1e-6)
  else:  # v1: that of the babbling pose nearest the goal, which it trained to reach.
    dataset = data.collect(
      ROBOT, samples=TINY.samples, seed=inverse_training.DATA_SEED, progress=False
    )
    poses = completion.Candidates.from_dataset(dataset).poses[:, 0]
    nearest = poses[np.argmin(np.linalg.norm(poses[:, :3] - goal[0], axis=1))]
    np.testing.assert_allclose(target[3:], nearest[3:], rtol=1e-6)
    assert not np.allclose(nearest[3:], start[0, 3:])
