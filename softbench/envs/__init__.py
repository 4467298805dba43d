"""softbench's tasks as Gymnasium environments.

Importing this module registers, in Gymnasium's ``softbench`` namespace,

  softbench/<robot>-<task>-vN   every registered robot with every task of the suite
  softbench/SoftArm-vN          any robot and task: ``robot=`` and ``task=`` options

where vN is the installed physics version (``softbench.robots.versions``): v1 on MuJoCo 4, v0 on
the old stack (MuJoCo 3.17 with the cable plugin), so an id names the physics it simulates and
the v0 ids work where the old stack is installed. ``gymnasium.make("softbench/tendon-3-spiral-v1")``
works after ``import softbench.envs``, ``gymnasium.make_vec(id, num_envs=N)`` steps N arms at once
(``vector.SoftArmVectorEnv``, physics v1), and both work without any import as
``gymnasium.make("softbench.envs:softbench/tendon-3-spiral-v1")``
(Gymnasium 1.0 replaced entry-point plugins with this ``module:id`` form). Options go through
``gymnasium.make``: the task's (``length``, ``module``, ``steps``, ``trajectory``,
``initial_actuation``) and the environment's (``observation``, ``render_mode``, ``width``,
``height``, ``camera``); see ``environment.SoftArmEnv``.
"""

import importlib.util

import gymnasium

from softbench import robots
from softbench import suite
from softbench.envs.environment import SoftArmEnv
from softbench.robots import versions

NAMESPACE = "softbench"
VERSION = int(versions.current().name.removeprefix("v"))  # The ids' vN: the physics version.
ENTRY_POINT = "softbench.envs.environment:SoftArmEnv"
# MuJoCo 4's batch steps many arms at once; the old stack vectorizes SoftArmEnv one by one.
VECTOR_ENTRY_POINT = (
  "softbench.envs.vector:SoftArmVectorEnv" if importlib.util.find_spec("mujoco.batch") else None
)
ANY_ROBOT_ID = f"{NAMESPACE}/SoftArm-v{VERSION}"


def env_id(robot: str, task: str) -> str:
  """The Gymnasium id of ``task`` on the registered robot ``robot``."""
  return f"{NAMESPACE}/{robot}-{task}-v{VERSION}"


def env_ids() -> tuple[str, ...]:
  """Every registered (registered robot, task) id, ``custom`` included (it needs ``trajectory=``),
  tasks registered after this module's import too."""
  return tuple(env_id(robot, task) for robot in robots.REGISTERED_ROBOTS for task in suite.TASKS)


def _register_task(task: str) -> None:
  """Registers ``task``'s id on every registered robot (once: importing again changes nothing)."""
  for robot in robots.REGISTERED_ROBOTS:
    if env_id(robot, task) not in gymnasium.registry:
      gymnasium.register(
        env_id(robot, task),
        ENTRY_POINT,
        vector_entry_point=VECTOR_ENTRY_POINT,
        kwargs={"robot": robot, "task": task},
      )


if ANY_ROBOT_ID not in gymnasium.registry:
  gymnasium.register(ANY_ROBOT_ID, ENTRY_POINT, vector_entry_point=VECTOR_ENTRY_POINT)
for _task in suite.TASKS:
  _register_task(_task)
suite.on_register(_register_task)  # A task that suite.register adds later gets its ids too.

__all__ = ["ANY_ROBOT_ID", "NAMESPACE", "SoftArmEnv", "env_id", "env_ids"]
