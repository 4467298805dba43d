"""``SoftArmPhysics``: dm_control physics of a softbench arm, with named accessors.

Everything it needs comes from the MJCF itself (tip sites ``module{k}_tip`` and the
``action_map`` numeric), so it drives an exported model file as well as a freshly built robot.
"""

from dm_control import mujoco
import mujoco as mj
import numpy as np

from softbench.robots import base
from softbench.robots import chain


class SoftArmPhysics(mujoco.Physics):
  """Physics with per-module pose accessors and the robot's action map.

  ``step(n)`` is exactly ``mj_step(model, data, n)`` (as ``PoseRecorder`` and ``ArmBatch`` run
  it, so replaying a recorded action sequence reproduces its poses bit for bit), followed by
  ``mj_kinematics`` so that the pose accessors read the state after the step; in a suite
  environment on physics v0, dm_control's legacy stepping instead (``versions``).
  """

  legacy_step = False  # dm_control's Environment sets it: versions.PhysicsVersion.legacy_step.

  @classmethod
  def from_robot(cls, robot: base.SoftArm) -> "SoftArmPhysics":
    return cls.from_xml_string(robot.to_xml())

  @property
  def action_map(self) -> np.ndarray:
    """(num_actuators, 4): action index, then control at action -1, 0 and +1."""
    return self.model.numeric(base.ACTION_MAP_NAME).data.reshape(-1, 4)

  @property
  def action_dim(self) -> int:
    return int(self.action_map[:, 0].max()) + 1

  @property
  def num_modules(self) -> int:
    """How many tip sites ``module1_tip``, ``module2_tip``, ... the model has (by name lookup:
    rewards read this every step)."""
    count = 0
    while mj.mj_name2id(self.model.ptr, mj.mjtObj.mjOBJ_SITE, chain.tip_site_name(count + 1)) >= 0:
      count += 1
    return count

  def set_action(self, action: np.ndarray) -> None:
    """Sets the controls of every actuator from an action in [-1, 1]^action_dim.

    Raises:
      ValueError: not real numbers (bool, complex, text), wrong shape, or an action entry that
        is NaN, infinite or outside [-1, 1].
    """
    action = base.checked_actions(action, (self.action_dim,))
    self.data.ctrl[:] = base.action_to_ctrl(self.action_map, action)

  def step(self, nstep: int = 1) -> None:
    super().step(nstep)
    mj.mj_kinematics(self.model.ptr, self.data.ptr)

  def module_tip_position(self, module: int) -> np.ndarray:
    """World position (m) of module ``module``'s tip (1-based)."""
    return self.named.data.site_xpos[chain.tip_site_name(module)].copy()

  def module_orientation_vector(self, module: int) -> np.ndarray:
    """Unit arm axis at module ``module``'s tip, in world coordinates."""
    return self.named.data.site_xmat[chain.tip_site_name(module)].reshape(3, 3)[:, 2].copy()

  def module_poses(self) -> np.ndarray:
    """(num_modules, 6): tip position (m) and orientation vector of every module."""
    return np.stack(
      [
        np.concatenate([self.module_tip_position(k), self.module_orientation_vector(k)])
        for k in range(1, self.num_modules + 1)
      ]
    )
