"""``sac``: Soft Actor-Critic (Stable-Baselines3), a model-free agent that learns by acting on the
simulated arm through softbench's Gymnasium environment, not from a model of it.

Training: ``STEPS[profile]`` environment steps of episodes that each follow ``EPISODE_STEPS``
consecutive poses of the babbling dataset's training split (``envs.streams``: random reachable
targets, the data the supervised agents learn from; the ``babbling`` task scores held-out ones).
From physics v1 it trains on ``VECTOR_ENVS`` arms at once, myopically (``gamma`` 0) on the
``distance`` reward (``VECTOR_HYPERPARAMETERS`` says why); v0's records were trained on one arm
with the task's reward and ``gamma`` 0.9. It acts on the task's observation (``SoftArmEnv``'s
flat form), with positions in arm lengths (``policy_input``). The trained model is cached in the
data home like every checkpoint, with the environment steps and wall time it took; an interrupted
training resumes from its saved state (model, optimisers, replay buffer, random generators; saved
at least every ``snapshots.SAVE_INTERVAL_S``) to the same weights as an uninterrupted one.
"""

from collections.abc import Callable
import dataclasses
import io
import pathlib
import random
import time

import numpy as np
import stable_baselines3
from stable_baselines3.common import logger as sb3_logger
from stable_baselines3.common import vec_env
import torch

from smpl import fitting
from smpl import snapshots
from softbench import data
from softbench import profiles
from softbench import progress as progress_bars
from softbench import storage
from softbench.agents import base
from softbench.agents import completion
from softbench.agents import learned
from softbench.agents import sb3_vector
from softbench.envs import environment
from softbench.envs import streams
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training
from softbench.robots import base as robot_base
from softbench.robots import recorder
from softbench.robots import versions
from softbench.suite import trajectories

EPISODE_STEPS = 50  # Control steps (targets) per training episode.
STEPS = {"paper": 300_000, "default": 30_000, "tiny": 100}  # Environment steps per profile.
LEARNING_STARTS = {"paper": 5_000, "default": 2_000, "tiny": 50}  # Random steps before learning.
CHUNK_STEPS = 1_000  # Steps per arm per `learn` call; the state may be saved after each (a
# multiple of EPISODE_STEPS, so that saves fall between episodes).
HYPERPARAMETERS = {
  "learning_rate": 3e-4,
  "batch_size": 256,
  "tau": 0.005,
  "train_freq": 1,
  "gradient_steps": 1,
  # The pose after a step depends mostly on that step's action (the arms settle within one
  # control period, tendon-5 in 0.72 s of 1 s), so little reward lies beyond a few steps.
  "gamma": 0.9,
  "net_arch": (256, 256),
  # The task's reward is small far from the target (0.02 at 24 % of the arm length), next to
  # SAC's entropy bonus: scaled by the running std of the discounted return (SB3's
  # VecNormalize, rewards only), a 6,000-step probe on tendon-1 tracked the spiral to 7.7 mm
  # (unscaled: 12.1 mm; the zero agent 12.9 mm) and the babbling task to 13.1 mm (24.8; 27.5).
  "normalise_reward": True,
}
TRAINING_VERSION = 1  # Bump when training changes, so that cached models are not reused.
# From physics v1 SAC trains on VECTOR_ENVS arms stepped at once (envs.streams'
# TargetStreamVectorEnv through sb3_vector), one gradient step per environment step as before;
# v0 keeps the one-arm training its records were made with (TRAINING_VERSION 1, same keys).
VECTOR_ENVS = 8
VECTOR_TRAINING_VERSION = 3
VECTOR_HYPERPARAMETERS = {
  "num_envs": VECTOR_ENVS,
  "gradient_steps": VECTOR_ENVS,
  # A step's pose depends on its own action and hardly on earlier ones (the arms settle within
  # the control period), and the next targets are random: the best policy is myopic, and a
  # critic of the one-step reward needs no bootstrapping from a moving target.
  "gamma": 0.0,
  # Minus the mean distance to the targets in arm lengths (envs.streams), dense where the task's
  # tolerance reward flattens out. Probes on tendon-3 (seed 0, 8 arms, spiral, 2026-12-07; the
  # zero agent 19.37 mm): gamma 0.9 and the task's reward 24.81 mm at 30,000 steps; gamma 0 and
  # the task's reward 12.97, 8.27, 5.81 mm at 5,000, 10,000, 15,000 steps; gamma 0 and this
  # reward 3.36, 3.81, 3.89, 3.30, 2.90, 2.60 mm at 5,000 .. 30,000.
  "training_reward": "distance",
}
SPENT = ("environment_steps", "episodes", "wall_time_s")  # What a trained model records of its
# training (training_summary).
_FORMAT = "softbench-sac"
# torch.save's default pickle protocol (2) writes a bytes object as a latin-1 string, two bytes
# for every byte above 127: a tendon-3 model's 3.5 MB of SB3 zip took 5.1 MB on disk. Protocol 4
# writes bytes as they are.
_PICKLE_PROTOCOL = 4


def policy_input(flat: np.ndarray, shapes: dict[str, tuple[int, ...]], length: float) -> np.ndarray:
  """The policy's input: a flat observation (``environment.flatten``) of parts of ``shapes``,
  every position (the first 3 columns of poses and targets) divided by the arm ``length`` (m),
  as float32."""
  scaled = np.array(flat, dtype=np.float32)
  for key, part in environment.layout(shapes).items():
    if key in ("poses", "target"):
      rows = scaled[part].reshape(shapes[key])
      rows[:, :3] /= length
      scaled[part] = rows.ravel()
  return scaled


@dataclasses.dataclass(frozen=True)
class SacConfig:
  """Everything a trained model depends on; its hash names the checkpoint."""

  robot: str
  robot_xml_sha256: str
  samples: int
  seed: int
  steps: int
  learning_starts: int
  episode_steps: int
  hyperparameters: tuple
  stable_baselines3: str
  training_version: int = TRAINING_VERSION

  @property
  def key(self) -> str:
    return storage.config_key(self, f"sac-{self.robot}-seed{self.seed}")


def _on_first_physics() -> bool:
  """Whether the installed physics is v0, whose records sac made on one arm, with the task's
  reward and the hold rule."""
  return versions.current().name == versions.FIRST


def training_config(robot: robot_base.SoftArm, seed: int, profile: profiles.Profile) -> SacConfig:
  one_arm = _on_first_physics()
  hyperparameters = HYPERPARAMETERS if one_arm else {**HYPERPARAMETERS, **VECTOR_HYPERPARAMETERS}
  return SacConfig(
    robot.name,
    robot.physics_sha256(),
    profile.samples,
    seed,
    STEPS[profile.name],
    LEARNING_STARTS[profile.name],
    EPISODE_STEPS,
    tuple(sorted(hyperparameters.items())),
    stable_baselines3.__version__.split(".")[0],
    TRAINING_VERSION if one_arm else VECTOR_TRAINING_VERSION,
  )


def num_envs(config: SacConfig) -> int:
  """The arms ``config``'s training steps at once."""
  return dict(config.hyperparameters).get("num_envs", 1)


def checkpoint_path(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile
) -> pathlib.Path:
  """Where the trained model of ``seed`` is cached (it exists once trained)."""
  key = training_config(robot, seed, profile).key
  return storage.softbench_home() / checkpoints.CHECKPOINT_FOLDER / f"{key}.pt"


class _PolicyInput(vec_env.VecEnvWrapper):
  """The training environments' observations as ``policy_input``."""

  def __init__(self, venv: vec_env.VecEnv, shapes: dict[str, tuple[int, ...]], length: float):
    low = policy_input(venv.observation_space.low, shapes, length)
    high = policy_input(venv.observation_space.high, shapes, length)
    space = type(venv.observation_space)(low, high, dtype=np.float32)
    super().__init__(venv, observation_space=space)
    self._shapes, self._length = shapes, length

  def _scaled(self, observations: np.ndarray) -> np.ndarray:
    return np.stack([policy_input(row, self._shapes, self._length) for row in observations])

  def reset(self):
    return self._scaled(self.venv.reset())

  def step_wait(self):
    observations, rewards, dones, infos = self.venv.step_wait()
    return self._scaled(observations), rewards, dones, infos


def _training_env(
  robot: robot_base.SoftArm, config: SacConfig, first_episode: int
) -> tuple[vec_env.VecEnv, streams.TargetStreamEnv | streams.TargetStreamVectorEnv]:
  dataset = data.collect(
    robot.name, samples=config.samples, seed=inverse_training.DATA_SEED, progress=False
  )
  targets = streams.training_targets(dataset, EPISODE_STEPS)
  values = dict(config.hyperparameters)
  reward = values.get("training_reward", "task")
  if num_envs(config) == 1:
    stream_env = streams.TargetStreamEnv(
      robot, targets, EPISODE_STEPS, config.seed, first_episode, reward
    )
    venv = vec_env.DummyVecEnv([lambda: stream_env])
  else:
    # The CPU backend on every machine: its physics is the serial path's bit for bit, so that a
    # seed trains to the same weights with or without a GPU (MuJoCo Warp computes in float32).
    stream_env = streams.TargetStreamVectorEnv(
      num_envs(config),
      robot,
      targets,
      EPISODE_STEPS,
      config.seed,
      first_episode,
      reward,
      backend="cpu",
    )
    venv = sb3_vector.GymnasiumVecEnv(stream_env)
  scaled = _PolicyInput(venv, stream_env.observation_shapes, robot.length)
  if values["normalise_reward"]:
    scaled = vec_env.VecNormalize(scaled, norm_obs=False, norm_reward=True, gamma=values["gamma"])
  return scaled, stream_env


def _model_kwargs(config: SacConfig) -> dict:
  values = dict(config.hyperparameters)
  unused = ("net_arch", "normalise_reward", "num_envs", "training_reward")
  return {
    **{key: value for key, value in values.items() if key not in unused},
    "policy_kwargs": {"net_arch": list(values["net_arch"])},
  }


def _reward_scale(venv: vec_env.VecEnv) -> dict | None:
  """The running statistics of the reward normalisation, if any."""
  if not isinstance(venv, vec_env.VecNormalize):
    return None
  return {
    "mean": venv.ret_rms.mean,
    "var": venv.ret_rms.var,
    "count": venv.ret_rms.count,
    "returns": venv.returns,
  }


def _restore_reward_scale(venv: vec_env.VecEnv, saved: dict | None) -> None:
  if saved is not None:
    venv.ret_rms.mean, venv.ret_rms.var = saved["mean"], saved["var"]
    venv.ret_rms.count, venv.returns = saved["count"], saved["returns"]


def _random_states(model) -> dict:
  numpy_state = np.random.get_state(legacy=False)
  return {
    "torch": torch.get_rng_state(),
    "numpy": numpy_state,
    "python": random.getstate(),
    "action_space": model.action_space.np_random.bit_generator.state,
  }


def _restore_random_states(model, states: dict) -> None:
  torch.set_rng_state(states["torch"])
  np.random.set_state(states["numpy"])
  random.setstate(states["python"])
  model.action_space.np_random.bit_generator.state = states["action_space"]


def _read(path: pathlib.Path, config: SacConfig, kind: str) -> dict:
  """The saved dict at ``path``, checked to be of ``kind`` and made for ``config``."""
  saved = torch.load(path, map_location="cpu", weights_only=False)
  if (
    not isinstance(saved, dict)
    or saved.get("format") != _FORMAT
    or saved.get("kind") != kind
    or saved.get("config") != dataclasses.asdict(config)
  ):
    raise ValueError("not a sac model of this configuration")
  return saved


def _save_state(
  path: pathlib.Path,
  config: SacConfig,
  model,
  stream_env,
  elapsed: float,
  last_observation: np.ndarray,
) -> None:
  model_bytes, buffer_bytes = io.BytesIO(), io.BytesIO()
  model.save(model_bytes)
  model.save_replay_buffer(buffer_bytes)
  state = {
    "format": _FORMAT,
    "kind": "training-state",
    "config": dataclasses.asdict(config),
    "model": model_bytes.getvalue(),
    "replay_buffer": buffer_bytes.getvalue(),
    "random": _random_states(model),
    "reward_scale": _reward_scale(model.get_env()),
    # Saves fall between episodes: the ones under way (one per arm) have just begun, and a
    # resumed training begins them again, at the observation the model holds.
    "episode_under_way": stream_env.episodes_started - num_envs(config),
    "last_observation": last_observation,
    "wall_time_s": elapsed,
  }
  content = io.BytesIO()
  torch.save(state, content, pickle_protocol=_PICKLE_PROTOCOL)
  storage.write_cache_file(path, content.getvalue(), "sac training state")


def train(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool = False
) -> dict:
  """The trained model of ``seed`` (its saved dict): from the cache, or trained now (resuming a
  saved state) and cached; another process sharing the data home waits meanwhile
  (``storage.found_or_made``) and then loads it."""
  config = training_config(robot, seed, profile)
  path = checkpoint_path(robot, seed, profile)
  return storage.found_or_made(
    path,
    lambda: storage.read_cached(
      path, lambda file: _read(file, config, "model"), "cached sac model", "training it again"
    ),
    lambda: _trained(robot, seed, profile, show_progress),
    "sac model",
  )


def _trained(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool
) -> dict:
  """``train``'s model, trained now (resuming a saved state) and cached."""
  config = training_config(robot, seed, profile)
  path = checkpoint_path(robot, seed, profile)
  partial = path.with_suffix(".partial.pt")
  state = storage.read_cached(
    partial,
    lambda file: _read(file, config, "training-state"),
    "sac training state",
    "training from the start",
  )
  device = fitting.default_device()
  with fitting.limited_cpu_threads(fitting.CPU_THREADS, device):
    venv, stream_env = _training_env(robot, config, state["episode_under_way"] if state else 0)
    if state is None:
      model = stable_baselines3.SAC(
        "MlpPolicy",
        venv,
        seed=seed,
        device=device,
        buffer_size=config.steps,
        learning_starts=config.learning_starts,
        **_model_kwargs(config),
      )
      elapsed = 0.0
    else:
      model = stable_baselines3.SAC.load(io.BytesIO(state["model"]), env=venv, device=device)
      model.load_replay_buffer(io.BytesIO(state["replay_buffer"]))
      _restore_random_states(model, state["random"])
      model._last_obs = first = venv.reset()  # pylint: disable=protected-access
      _restore_reward_scale(venv, state["reward_scale"])  # After the reset, which zeroes returns.
      if isinstance(venv, vec_env.VecNormalize):
        model._last_original_obs = venv.get_original_obs()  # pylint: disable=protected-access
      if not np.array_equal(first, state["last_observation"]):
        raise RuntimeError(
          f"{partial}: the resumed episode does not start where the saved "
          "training stopped; delete the file to train from the start"
        )
      elapsed = state["wall_time_s"]
    # SB3's own logger would make a folder in the temporary directory at every learn() call.
    model.set_logger(sb3_logger.Logger(folder=None, output_formats=[]))
    started, saved_at = time.perf_counter() - elapsed, time.monotonic()
    with progress_bars.SampleProgress(
      f"sac {robot.name} seed {seed}", config.steps, model.num_timesteps, show_progress
    ) as bar:
      while model.num_timesteps < config.steps:
        chunk = min(CHUNK_STEPS * num_envs(config), config.steps - model.num_timesteps)
        model.learn(chunk, reset_num_timesteps=False)
        bar.update(model.num_timesteps)
        if (
          model.num_timesteps < config.steps
          and time.monotonic() - saved_at >= snapshots.SAVE_INTERVAL_S
        ):
          _save_state(
            partial, config, model, stream_env, time.perf_counter() - started, model._last_obs
          )  # pylint: disable=protected-access
          saved_at = time.monotonic()
  model_bytes = io.BytesIO()
  model.save(model_bytes, exclude=["replay_buffer"])
  finished = {
    "format": _FORMAT,
    "kind": "model",
    "config": dataclasses.asdict(config),
    "model": model_bytes.getvalue(),
    "environment_steps": int(model.num_timesteps),
    "episodes": stream_env.episodes_started,
    "wall_time_s": round(time.perf_counter() - started, 3),
  }
  content = io.BytesIO()
  torch.save(finished, content, pickle_protocol=_PICKLE_PROTOCOL)
  storage.write_cache_file(path, content.getvalue(), "cached sac model")
  partial.unlink(missing_ok=True)
  return finished


class SACAgent(base.Agent):
  """Acts with a trained SAC policy, deterministically (the mean action).

  It was trained to reach whole-arm poses: a task that scores some modules, or positions only
  (reach), has its target completed. With ``candidates`` (physics v1) as the learned agents'
  ``nearest`` helper does (``agents.completion``): the babbling training pose whose given part
  lies nearest the goal (the poses it trained to reach), a still goal corrected from the measured
  error. Without (v0, whose records were made so) by the ``hold`` rule: every module's starting
  pose, the scored modules' given parts replaced by the target; a whole-arm target no action
  reaches where the given module moves far (tendon-3's reach: 70.81 mm against 79.39 for
  the zero agent).
  """

  def __init__(
    self,
    robot: robot_base.SoftArm,
    seed: int,
    trained: dict,
    candidates: Callable[[], completion.Candidates] | None = None,
  ):
    super().__init__(robot, seed)
    self._model = stable_baselines3.SAC.load(io.BytesIO(trained["model"]), device="cpu")
    self._completer = None
    if candidates is not None:
      self._completer = completion.Completer(
        candidates, _no_forward_model, robot.length, robot.control_timestep
      )

  def reset(self, episode: base.EpisodeInfo) -> None:
    self._scored = np.array(episode.scored_modules) - 1
    self._start = None
    if self._completer is not None:
      self._completer.reset()

  def _whole_target(self, given: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Every module's target pose for the ``given`` part (class docstring)."""
    if len(self._scored) == self.robot.num_modules and given.shape[1] == recorder.POSE_SIZE:
      return given
    if self._completer is not None:
      return self._completer.complete(
        given,
        trajectories.Given.of_target(self._scored, given),
        poses,
        poses,
        np.ones(self.robot.action_dim, bool),
        refine=False,
      )
    target = self._start.copy()
    target[self._scored, : given.shape[1]] = given
    return target

  def act(self, observation: dict) -> np.ndarray:
    poses = np.array(observation["poses"], dtype=float)
    if self._start is None:
      self._start = poses
    target = self._whole_target(np.asarray(observation["target"], dtype=float), poses)
    whole = {**observation, "target": target}
    shapes = {key: np.shape(whole[key]) for key in environment.KEYS}
    action, _ = self._model.predict(
      policy_input(environment.flatten(whole), shapes, self.robot.length), deterministic=True
    )
    return np.asarray(action, dtype=np.float64)


def _no_forward_model(*_) -> None:
  raise RuntimeError("sac completes targets without refinement: it has no forward model")


def build(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool = False
) -> base.Agent:
  trained = train(robot, seed, profile, show_progress)
  holds = _on_first_physics()  # v0's records completed targets by the hold rule.
  candidates = None if holds else lambda: learned.babbling_candidates(robot, profile)
  return SACAgent(robot, seed, trained, candidates)


def training_summary(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile
) -> dict | None:
  """The environment steps, episodes and wall time of ``seed``'s cached model; None if absent."""
  config = training_config(robot, seed, profile)
  saved = storage.read_cached(
    checkpoint_path(robot, seed, profile),
    lambda file: _read(file, config, "model"),
    "cached sac model",
    "training it again",
  )
  return None if saved is None else {key: saved[key] for key in SPENT}
