"""A softbench task on many arms at once: ``SoftArmVectorEnv``, Gymnasium's ``VectorEnv``.

``gymnasium.make_vec("softbench/tendon-3-spiral-v1", num_envs=N)`` makes one (physics v1; on the
old stack ``make_vec`` vectorizes ``SoftArmEnv`` one by one). Its sub-environments are
``SoftArmEnv``s stepped together: every call holds each arm's action for one control period in
one ``ArmBatch`` call (``softbench.robots.batch``: the ``cpu`` backend on MuJoCo's thread pool,
``warp`` on a GPU), and the observations, rewards, ends and ``info`` of each arm are those its
``SoftArmEnv`` gives, bit for bit on the ``cpu`` backend (``tests/test_vector_env.py`` compares
it with ``gymnasium.vector.SyncVectorEnv`` of ``SoftArmEnv``s, autoresets included).

``reset(seed=s)`` starts sub-environment i as ``SoftArmEnv.reset(seed=s + i)`` does (a list gives
each its own), and ``options={"reset_mask": mask}`` resets only the masked ones. Autoreset is
Gymnasium 1.x's ``autoreset_mode`` (default ``NEXT_STEP``: the step after an episode's end resets
that arm, ignores its action and returns reward 0; ``SAME_STEP``: the ending step resets it and
puts the last observation and info in ``info["final_obs"]`` and ``info["final_info"]``;
``DISABLED``: the caller resets with a mask).
"""

from typing import Any

import gymnasium
from gymnasium.vector import utils as vector_utils
from gymnasium.vector.vector_env import AutoresetMode
import numpy as np

from softbench import robots
from softbench import suite
from softbench.data import seeding
from softbench.envs import environment
from softbench.robots import batch as arm_batch
from softbench.suite import base as task_base


class SoftArmVectorEnv(gymnasium.vector.VectorEnv):
  """``task`` on ``num_envs`` arms of ``robot`` (a name or a ``robots.SoftArm``).

  Args:
    num_envs: how many arms.
    robot, task, observation, **task_options: as ``SoftArmEnv`` takes them.
    backend: ``ArmBatch``'s backend (``robots.batch.BACKENDS``).
    threads: the ``cpu`` backend's threads (all cores if None).
    autoreset_mode: an ``AutoresetMode`` (or its value).

  Raises:
    ValueError: an argument ``SoftArmEnv`` or ``ArmBatch`` refuses, or a bad ``num_envs`` or
      autoreset mode (one line).
  """

  metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

  def __init__(
    self,
    num_envs: int,
    robot: str | robots.SoftArm,
    task: str,
    observation: str = "flat",
    backend: str = "auto",
    threads: int | None = None,
    autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
    **task_options,
  ):
    try:
      self.autoreset_mode = AutoresetMode(autoreset_mode)
    except ValueError:
      modes = ", ".join(mode.value for mode in AutoresetMode)
      raise ValueError(f"autoreset_mode must be one of {modes}, got {autoreset_mode!r}") from None
    arm = robots.make(robot) if isinstance(robot, str) else robot
    self.batch = arm_batch.make(arm, num_envs, backend=backend, threads=threads)
    template = environment.SoftArmEnv(arm, task, observation, **task_options)
    self.robot = template.robot
    self.task_name = task
    self._task_options = task_options
    self._observation_form = observation
    self.single_observation_space = template.observation_space
    self.single_action_space = template.action_space
    self.observation_shapes = template.observation_shapes
    self.observation_layout = template.observation_layout
    self.num_envs = self.batch.num_arms
    self.observation_space = vector_utils.batch_space(self.single_observation_space, num_envs)
    self.action_space = vector_utils.batch_space(self.single_action_space, num_envs)
    self.metadata = {**self.metadata, "autoreset_mode": self.autoreset_mode}
    self.render_mode = None
    self.tasks = [self.new_task(index) for index in range(self.num_envs)]
    self._started = np.zeros(self.num_envs, bool)  # Arms whose episode runs or just ended.
    self._ended = np.zeros(self.num_envs, bool)
    self._observations = [None] * self.num_envs

  def new_task(self, arm: int) -> task_base.SoftArmTask:
    """Arm ``arm``'s task object, as ``SoftArmEnv`` builds it (unseeded until a seeded reset)."""
    return suite.build_task(self.robot, self.task_name, **self._task_options)[1]

  def episode_task(self, arm: int, seed: int | None) -> task_base.SoftArmTask:
    """The task that arm ``arm``'s next episode runs: its own, reseeded with ``seed`` if given
    (``SoftArmEnv.reset(seed=)``). A subclass may give a new one per episode."""
    if seed is not None:
      seeding.check_seed(seed)
      self.tasks[arm].reseed(seed)
    return self.tasks[arm]

  def _seeds(self, seed: int | list | None) -> list:
    if seed is None:
      return [None] * self.num_envs
    if isinstance(seed, int | np.integer) and not isinstance(seed, bool):
      return [int(seed) + index for index in range(self.num_envs)]
    seeds = list(seed)
    if len(seeds) != self.num_envs:
      raise ValueError(f"seed must be None, an int or {self.num_envs} seeds, got {len(seeds)}")
    return seeds

  def reset(self, *, seed: int | list | None = None, options: dict[str, Any] | None = None):
    """Starts episodes (module docstring); returns the batched observation and ``{}``-like
    infos."""
    options = dict(options or {})
    mask = options.pop("reset_mask", None)
    if options:
      raise ValueError(f"reset takes only the option reset_mask, got {sorted(options)}")
    if mask is None:
      mask = np.ones(self.num_envs, bool)
    elif not isinstance(mask, np.ndarray) or mask.dtype != bool or mask.shape != (self.num_envs,):
      raise ValueError(f"reset_mask must be a bool array of shape ({self.num_envs},)")
    seeds = self._seeds(seed)
    if isinstance(seed, int | np.integer) and not isinstance(seed, bool):
      self._np_random, self._np_random_seed = gymnasium.utils.seeding.np_random(int(seed))
    arms = np.flatnonzero(mask)
    self._start(arms, [seeds[arm] for arm in arms], actions=None, running=np.empty(0, int))
    return self._batched(self._observations), {}

  def _start(self, starting: np.ndarray, seeds: list, actions, running: np.ndarray) -> None:
    """Starts episodes on the arms ``starting`` while ``running`` hold their ``actions``, in one
    batch call; fills ``self._observations`` of the starting arms."""
    tasks = {arm: self.episode_task(arm, seed) for arm, seed in zip(starting, seeds)}
    initial = {arm: task.start_episode() for arm, task in tasks.items()}
    holding = [arm for arm in starting if tasks[arm].holds_initial_action]
    self.batch.reset(starting)
    arms = np.concatenate([running, holding]).astype(int)
    if len(arms):
      held = [actions[arm] for arm in running] + [initial[arm] for arm in holding]
      self.batch.hold(np.asarray(held, dtype=np.float64), arms)
    self.batch.set_time(0.0, starting)
    for arm, poses in zip(starting, self.batch.poses(starting)):
      self.tasks[arm] = tasks[arm]
      tasks[arm].episode_started(poses)
      self._observations[arm] = tasks[arm].observation_from(poses)
    self._started[starting] = True
    self._ended[starting] = False

  def step(self, actions):
    """Steps every arm one control period; Gymnasium's batched (observation, reward,
    terminated, truncated, info)."""
    actions = np.asarray(actions)
    if actions.shape != self.action_space.shape:
      raise ValueError(f"actions must have shape {self.action_space.shape}, got {actions.shape}")
    if not np.all(self._started):
      raise RuntimeError("every arm's episode must have started; call reset() first")
    resetting = self._ended & (self.autoreset_mode == AutoresetMode.NEXT_STEP)
    if np.any(self._ended & ~resetting):
      raise RuntimeError("an arm's episode has ended; reset it (autoreset_mode DISABLED)")
    running = np.flatnonzero(~resetting)
    self.batch.controls(actions[running], len(running))  # Refuses bad actions before any change.
    actions = np.asarray(actions, np.float64)
    targets = {arm: self.tasks[arm].targets_at(self.tasks[arm].steps_done) for arm in running}
    for arm in running:
      self.tasks[arm].take_action(actions[arm])
    starting = np.flatnonzero(resetting)
    self._start(starting, [None] * len(starting), actions, running)
    rewards = np.zeros(self.num_envs)
    infos: dict[str, Any] = {}
    ending = []
    reached = self.batch.poses(running)
    for arm in running:
      self.tasks[arm].after_step()
    scores = zip(running, *self._scores(running, reached, targets), reached)
    for arm, reward, info, poses in scores:
      task = self.tasks[arm]
      rewards[arm] = reward
      self._observations[arm] = task.observation_from(poses)
      self._ended[arm] = task.get_termination(None) is not None
      if self._ended[arm] and self.autoreset_mode == AutoresetMode.SAME_STEP:
        info = {"final_obs": self._single(self._observations[arm]), "final_info": info}
        ending.append(arm)
      infos = self._add_info(infos, info, arm)
    truncated = self._ended.copy()
    if ending:
      ending = np.array(ending)
      self._start(ending, [None] * len(ending), None, np.empty(0, int))
      for arm in ending:
        infos = self._add_info(infos, {}, arm)
    terminated = np.zeros(self.num_envs, bool)
    return self._batched(self._observations), rewards, terminated, truncated, infos

  def _scores(self, arms: np.ndarray, poses: np.ndarray, targets: dict) -> tuple[list, list]:
    """Each arm's reward and info (``environment.errors``) after a step, computed for all arms at
    once where their tasks score the same modules on targets of one shape and keep the base
    class's reward (every arm of a task, as a rule), arm by arm otherwise: 260 us of Python an
    arm a step when all was arm by arm, 84 with the errors batched (64 arms of tendon-1)."""
    tasks = [self.tasks[arm] for arm in arms]
    shown = [targets[arm] for arm in arms]
    alike = {(task.scored_modules(), target.shape) for task, target in zip(tasks, shown)}
    base_reward = all(type(task).reward_from is task_base.SoftArmTask.reward_from for task in tasks)
    if len(alike) != 1 or not base_reward:
      return (
        [task.reward_from(pose) for task, pose in zip(tasks, poses)],
        [
          environment.errors(self.robot, task, pose, target)
          for task, pose, target in zip(tasks, poses, shown)
        ],
      )
    stacked = np.stack(shown)
    scored = np.array(tasks[0].scored_modules()) - 1
    rewards = task_base.position_reward(poses[:, scored, :3], stacked, self.robot.length)
    batched = environment.errors(self.robot, tasks[0], poses, stacked)
    infos = [
      {key: value if key == "scored_modules" else value[index] for key, value in batched.items()}
      for index in range(len(arms))
    ]
    return [float(reward) for reward in rewards], infos

  def _single(self, named: dict) -> np.ndarray | dict:
    return environment.observation_in(named, self._observation_form)

  def _batched(self, observations: list) -> np.ndarray | dict:
    singles = [self._single(named) for named in observations]
    if self._observation_form == "dict":
      return {key: np.stack([single[key] for single in singles]) for key in environment.KEYS}
    return np.stack(singles)

  def close_extras(self, **kwargs) -> None:
    self.batch.close()
