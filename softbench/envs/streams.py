"""Episodes that follow stretches of a stream of reachable poses: what an agent that learns by
interaction (``softbench.agents.sac``) trains on.

The stream is the robot's babbling dataset, training split (the poses the supervised agents
learn from; the suite's ``babbling`` task follows held-out ones). Episode i follows
``episode_steps`` consecutive poses of one piece of that split, drawn, with its random start,
from the stream ``seeding.TARGET_STREAM_EPISODES`` at index i: the sequence of episodes is fixed
by the seed, so a training that resumes at episode i sees what it would have seen.

A step's reward is the task's (``REWARDS``: ``task``, the suite's tolerance reward) or
``distance``, minus the scored modules' mean distance to their targets in arm lengths: dense
everywhere, where the tolerance reward flattens out far from the target (0.02 at 24 % of the arm's
length).
"""

import gymnasium
from gymnasium.vector import AutoresetMode
import numpy as np

from softbench import metrics
from softbench import robots
from softbench import suite
from softbench.data import dataset as babbling_dataset
from softbench.data import seeding
from softbench.data import splits
from softbench.envs import environment
from softbench.envs import vector
from softbench.suite import base as task_base

REWARDS = ("task", "distance")  # What a training step may reward (module docstring).


def checked_reward(reward: str) -> str:
  """``reward``, if it is one of ``REWARDS``.

  Raises:
    ValueError: another reward (one line).
  """
  if reward not in REWARDS:
    raise ValueError(f"reward must be one of {', '.join(REWARDS)}, got {reward!r}")
  return reward


def distance_reward(info: dict, length: float) -> float:
  """The ``distance`` reward of a step whose ``info`` (``environment.errors``) scores an arm
  ``length`` (m) long: minus the scored modules' mean distance to their targets, in arm lengths."""
  return -float(np.mean(info["position_error_mm"])) / (length * metrics.MM_PER_M)


def training_targets(data: babbling_dataset.Dataset, episode_steps: int) -> list[np.ndarray]:
  """The pieces of ``data``'s training split long enough for an episode, as target poses
  (samples, num_modules, 6): the pose reached after each action."""
  pieces = splits.split_pieces(data.episode_lengths)["train"]
  targets = [piece.recording(data)[0][1:] for piece in pieces]
  usable = [piece for piece in targets if len(piece) >= episode_steps]
  if not usable:
    raise ValueError(
      f"no training piece of {data.path} holds {episode_steps} steps; collect "
      "more samples or shorten the episodes"
    )
  return usable


class EpisodeSequence:
  """The seed's sequence of episodes on ``stream``: episode i's targets and start seed.

  Raises:
    ValueError: a bad seed, or a piece of the stream shorter than ``episode_steps`` (one line).
  """

  def __init__(self, stream: list[np.ndarray], episode_steps: int, seed: int):
    seeding.check_seed(seed)
    if not all(len(piece) >= episode_steps for piece in stream) or not stream:
      raise ValueError(f"every piece of the stream needs at least {episode_steps} targets")
    self._stream = stream
    self._weights = np.array([len(piece) - episode_steps + 1 for piece in stream], float)
    self._weights /= self._weights.sum()
    self._episode_steps = episode_steps
    self._seed = seed

  def window(self, episode: int) -> tuple[np.ndarray, int]:
    """The targets (episode_steps, num_modules, 6) of ``episode`` and its start's seed."""
    draw = seeding.rng(self._seed, seeding.TARGET_STREAM_EPISODES, episode)
    piece = self._stream[draw.choice(len(self._stream), p=self._weights)]
    start = int(draw.integers(0, len(piece) - self._episode_steps + 1))
    return piece[start : start + self._episode_steps], int(draw.integers(0, seeding.MAX_SEED))


class TargetStreamEnv(gymnasium.Env):
  """``SoftArmEnv`` on the ``custom`` task, a new stretch of ``stream`` every episode.

  Args:
    robot: the robot.
    stream: pieces of target poses, each (samples, num_modules, 6), at least
      ``episode_steps`` long.
    episode_steps: control steps (targets) per episode.
    seed: seed of the episode sequence.
    first_episode: the index of the episode that the first ``reset`` starts (a resumed
      training's next one).
    reward: one of ``REWARDS``.

  ``reset``'s ``seed`` is not used: the episodes are the seed's sequence, in order.

  Raises:
    ValueError: a bad seed, stream or reward (one line).
  """

  metadata = {"render_modes": []}

  def __init__(
    self,
    robot: robots.SoftArm,
    stream: list[np.ndarray],
    episode_steps: int,
    seed: int,
    first_episode: int = 0,
    reward: str = "task",
  ):
    self.reward = checked_reward(reward)
    self._sequence = EpisodeSequence(stream, episode_steps, seed)
    self.robot = robot
    self.episode_steps = episode_steps
    self.episodes_started = first_episode
    self._env = environment.SoftArmEnv(robot, "custom", trajectory=stream[0][:episode_steps])
    self.observation_space = self._env.observation_space
    self.action_space = self._env.action_space
    self.observation_shapes = self._env.observation_shapes

  def window(self, episode: int) -> tuple[np.ndarray, int]:
    """The targets (episode_steps, num_modules, 6) of ``episode`` and its start's seed."""
    return self._sequence.window(episode)

  def reset(self, *, seed=None, options=None):
    del seed, options  # The episodes are the seed's sequence (class docstring).
    targets, start_seed = self.window(self.episodes_started)
    self.episodes_started += 1
    self._env = environment.SoftArmEnv(self.robot, "custom", trajectory=targets)
    return self._env.reset(seed=start_seed)

  def step(self, action):
    observation, reward, terminated, truncated, info = self._env.step(action)
    if self.reward == "distance":
      reward = distance_reward(info, self.robot.length)
    return observation, reward, terminated, truncated, info


class TargetStreamVectorEnv(vector.SoftArmVectorEnv):
  """``TargetStreamEnv`` on ``num_envs`` arms at once (``vector.SoftArmVectorEnv``, autoreset
  ``SAME_STEP``, as Stable-Baselines3 expects): every episode an arm starts is the next of the
  seed's sequence, the arms taking them in index order, so that a training that resumes at
  episode i sees what it would have seen. ``reset``'s seeds are not used.

  Args:
    num_envs: how many arms.
    robot, stream, episode_steps, seed, first_episode, reward: as ``TargetStreamEnv`` takes
      them.
    **options: ``SoftArmVectorEnv``'s (``backend``, ``threads``).
  """

  def __init__(
    self,
    num_envs: int,
    robot: robots.SoftArm,
    stream: list[np.ndarray],
    episode_steps: int,
    seed: int,
    first_episode: int = 0,
    reward: str = "task",
    **options,
  ):
    self.reward = checked_reward(reward)
    self._sequence = EpisodeSequence(stream, episode_steps, seed)
    self.episode_steps = episode_steps
    self.episodes_started = first_episode
    super().__init__(
      num_envs,
      robot,
      "custom",
      autoreset_mode=AutoresetMode.SAME_STEP,
      trajectory=stream[0][:episode_steps],
      **options,
    )

  def episode_task(self, arm: int, seed: int | None) -> task_base.SoftArmTask:
    del seed  # The episodes are the seed's sequence (class docstring).
    targets, start_seed = self._sequence.window(self.episodes_started)
    self.episodes_started += 1
    task = suite.build_task(self.robot, "custom", trajectory=targets)[1]
    task.reseed(start_seed)
    return task

  def _scores(self, arms: np.ndarray, poses: np.ndarray, targets: dict) -> tuple[list, list]:
    rewards, infos = super()._scores(arms, poses, targets)
    if self.reward == "distance":
      rewards = [distance_reward(info, self.robot.length) for info in infos]
    return rewards, infos
