"""softbench's tasks as Gymnasium environments.

Importing this module registers, in Gymnasium's ``softbench`` namespace,

  softbench/<robot>-<task>-v0   every benchmark robot with every task of the suite
  softbench/SoftArm-v0          any robot and task: ``robot=`` and ``task=`` options

so that ``gymnasium.make("softbench/tendon-3-spiral-v0")`` works after ``import softbench.envs``,
and without any import as ``gymnasium.make("softbench.envs:softbench/tendon-3-spiral-v0")``
(Gymnasium 1.0 replaced entry-point plugins with this ``module:id`` form). Options go through
``gymnasium.make``: the task's (``length``, ``module``, ``steps``, ``trajectory``,
``initial_actuation``) and the environment's (``observation``, ``render_mode``, ``width``,
``height``, ``camera``); see ``environment.SoftArmEnv``.
"""

import gymnasium

from softbench import robots
from softbench import suite
from softbench.envs.environment import SoftArmEnv

NAMESPACE = "softbench"
VERSION = 0
ENTRY_POINT = "softbench.envs.environment:SoftArmEnv"
ANY_ROBOT_ID = f"{NAMESPACE}/SoftArm-v{VERSION}"


def env_id(robot: str, task: str) -> str:
  """The Gymnasium id of ``task`` on the benchmark robot ``robot``."""
  return f"{NAMESPACE}/{robot}-{task}-v{VERSION}"


ENV_IDS = tuple(env_id(robot, task) for robot in robots.BENCHMARK_ROBOTS for task in suite.TASKS)
"""Every registered (benchmark robot, task) id, ``custom`` included (it needs ``trajectory=``)."""


def _register() -> None:
  for robot in robots.BENCHMARK_ROBOTS:
    for task in suite.TASKS:
      gymnasium.register(env_id(robot, task), ENTRY_POINT, kwargs={"robot": robot, "task": task})
  gymnasium.register(ANY_ROBOT_ID, ENTRY_POINT)


if env_id(robots.BENCHMARK_ROBOTS[0], suite.TASKS[0]) not in gymnasium.registry:
  _register()

__all__ = ["ANY_ROBOT_ID", "ENV_IDS", "NAMESPACE", "SoftArmEnv", "env_id"]
