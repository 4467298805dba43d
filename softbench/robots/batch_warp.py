"""The ``warp`` backend of ``ArmBatch``: MuJoCo Warp (``mujoco_warp``), every arm a world.

On a CUDA device one control period is one captured CUDA graph of ``steps_per_period`` steps;
on the CPU (Warp's ``cpu`` device, for tests) the steps run one by one. MuJoCo Warp computes in
float32 and supports dense Jacobians only up to 60 degrees of freedom, so arms with more (the
3-module tendon arms have 63) run with sparse ones: neither changes the physics beyond float32
rounding. Measured against the serial path on the CPU device: 2e-8 m on tendon-3's tips after
one control period from rest (``tests/test_batch.py`` holds tendon-1 and pneumatic-433 to
``PARITY_TOLERANCE_M`` where MuJoCo Warp is installed).
"""

import importlib.util

import mujoco
import numpy as np

from softbench.robots import base
from softbench.robots import batch

PARITY_TOLERANCE_M = 1e-6  # Tip positions within this of the serial path after a period.
DENSE_LIMIT = 60  # Degrees of freedom MuJoCo Warp's dense Jacobians support.


def installed() -> bool:
  """Whether MuJoCo Warp and Warp are installed (the ``gpu`` extra)."""
  return all(importlib.util.find_spec(name) for name in ("warp", "mujoco_warp"))


def cuda_available() -> bool:
  """Whether MuJoCo Warp is installed and Warp finds a CUDA device."""
  if not installed():
    return False
  import warp

  return warp.get_cuda_device_count() > 0


class WarpArmBatch(batch.ArmBatch):
  """``num_arms`` arms of ``robot`` as MuJoCo Warp worlds on ``device`` (default: Warp's)."""

  def __init__(self, robot: base.SoftArm, num_arms: int, device: str | None = None):
    if not installed():
      raise ValueError(
        "the warp backend needs MuJoCo Warp: make install-gpu (pip install softbench[gpu])"
      )
    import mujoco_warp
    import warp

    super().__init__(robot, num_arms)
    model = self.model
    if model.nv > DENSE_LIMIT:
      model.opt.jacobian = mujoco.mjtJacobian.mjJAC_SPARSE
    self._warp, self._mjw = warp, mujoco_warp
    self._device = warp.get_device(device)
    with warp.ScopedDevice(self._device):
      self._model = mujoco_warp.put_model(model)
      self._data = mujoco_warp.make_data(model, nworld=self.num_arms)
    self._graph = None
    self.reset()

  def _run_period(self) -> None:
    """Steps every world one control period (a CUDA graph, captured on first use)."""
    warp, mjw = self._warp, self._mjw
    with warp.ScopedDevice(self._device):
      if not self._device.is_cuda:
        for _ in range(self.steps_per_period):
          mjw.step(self._model, self._data)
        return
      if self._graph is None:
        with warp.ScopedCapture() as capture:
          for _ in range(self.steps_per_period):
            mjw.step(self._model, self._data)
        self._graph = capture.graph
      warp.capture_launch(self._graph)

  def _kinematics(self) -> None:
    with self._warp.ScopedDevice(self._device):
      self._mjw.kinematics(self._model, self._data)

  def reset(self, arms: batch.Arms = None) -> None:
    indices = self.arm_indices(arms)
    mask = np.zeros(self.num_arms, bool)
    mask[indices] = True
    with self._warp.ScopedDevice(self._device):
      self._mjw.reset_data(self._model, self._data, reset=self._warp.array(mask, dtype=bool))
    self._kinematics()

  def hold(self, actions: np.ndarray, arms: batch.Arms = None) -> None:
    indices = self.arm_indices(arms)
    controls = self.controls(actions, len(indices))
    others = np.setdiff1d(np.arange(self.num_arms), indices)
    fields = ("qpos", "qvel", "time", "ctrl")
    kept = {name: getattr(self._data, name).numpy()[others] for name in fields}
    ctrl = self._data.ctrl.numpy()
    ctrl[indices] = controls
    self._data.ctrl.assign(ctrl.astype(np.float32))
    self._run_period()
    if len(others):  # Worlds step together: the arms left out get their states back.
      for name, values in kept.items():
        field = getattr(self._data, name).numpy()
        field[others] = values
        getattr(self._data, name).assign(field)
    self._kinematics()
    qpos = self._data.qpos.numpy()[indices]
    if not np.all(np.isfinite(qpos)):
      bad = int(indices[np.argmax(~np.all(np.isfinite(qpos), axis=-1))])
      raise FloatingPointError(f"{self.robot.name}: simulation unstable in arm {bad}")

  def poses(self, arms: batch.Arms = None) -> np.ndarray:
    indices = self.arm_indices(arms)
    sites = self._sites
    poses = np.empty((len(indices), len(sites), batch.POSE_SIZE))
    poses[..., :3] = self._data.site_xpos.numpy()[indices][:, sites]
    xmat = self._data.site_xmat.numpy()[indices][:, sites].reshape(len(indices), len(sites), 3, 3)
    poses[..., 3:] = xmat[..., 2]
    return poses

  def set_time(self, time: float, arms: batch.Arms = None) -> None:
    field = self._data.time.numpy()
    field[self.arm_indices(arms)] = time
    self._data.time.assign(field)

  def close(self) -> None:
    self._graph = None
    self._data = None
