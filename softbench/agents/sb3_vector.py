"""A Gymnasium vector environment as Stable-Baselines3's ``VecEnv``: what lets an SB3 learner
(``sac``) train on many arms stepped at once (``softbench.envs.vector``).

SB3 resets an environment in the step that ends its episode and hands the last observation over
in ``info["terminal_observation"]``: Gymnasium's ``SAME_STEP`` autoreset, which the wrapped
environment must use. A truncated episode is marked ``TimeLimit.truncated``, so that SAC
bootstraps from its last observation instead of treating the end as terminal.
"""

from typing import Any

import gymnasium.vector
from gymnasium.vector import AutoresetMode
import numpy as np
from stable_baselines3.common import vec_env


class GymnasiumVecEnv(vec_env.VecEnv):
  """``env`` (a ``gymnasium.vector.VectorEnv`` with ``SAME_STEP`` autoreset) as an SB3 VecEnv.

  Raises:
    ValueError: ``env`` autoresets otherwise (one line).
  """

  def __init__(self, env: gymnasium.vector.VectorEnv):
    mode = env.metadata.get("autoreset_mode")
    if mode != AutoresetMode.SAME_STEP:
      raise ValueError(f"the vector environment must autoreset SAME_STEP for SB3, not {mode}")
    self.env = env  # Before VecEnv's own set-up, which reads its render_mode.
    super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
    self._actions = None

  def reset(self) -> np.ndarray:
    observations, _ = self.env.reset()
    self._reset_seeds()
    self._reset_options()
    return observations

  def step_async(self, actions: np.ndarray) -> None:
    self._actions = actions

  def step_wait(self):
    observations, rewards, terminated, truncated, info = self.env.step(self._actions)
    dones = terminated | truncated
    infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
    for arm in np.flatnonzero(dones):
      infos[arm]["terminal_observation"] = info["final_obs"][arm]
      infos[arm]["TimeLimit.truncated"] = bool(truncated[arm] and not terminated[arm])
    return observations, rewards.astype(np.float32), dones, infos

  def close(self) -> None:
    self.env.close()

  def get_attr(self, attr_name: str, indices=None) -> list:
    return [getattr(self.env, attr_name)] * len(self._get_indices(indices))

  def set_attr(self, attr_name: str, value, indices=None) -> None:
    setattr(self.env, attr_name, value)

  def env_method(self, method_name: str, *args, indices=None, **kwargs) -> list:
    return [getattr(self.env, method_name)(*args, **kwargs)] * len(self._get_indices(indices))

  def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
    return [False] * len(self._get_indices(indices))
