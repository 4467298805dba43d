"""Many arms of one robot stepped at once: ``ArmBatch``, one interface over two backends.

- ``cpu`` (``CpuArmBatch``): MuJoCo's own ``mujoco.batch.Batch`` (MuJoCo 4, physics v1), every
  arm a state row stepped on a persistent thread pool. Bit for bit the serial path
  (``SoftArmPhysics.set_action`` then ``step``: ``mj_step`` on one ``MjData`` per arm) at any
  thread count. On MuJoCo 3 (the old stack, physics v0), which has no ``mujoco.batch``,
  ``RolloutArmBatch`` does the same with ``mujoco.rollout`` (the arms have no constraints, so
  chaining rollouts through full physics states is bit for bit ``mj_step`` too).
- ``warp`` (``batch_warp.WarpArmBatch``): MuJoCo Warp, on a CUDA GPU where one is present (on the
  CPU, slowly, for tests); float32 arithmetic, within ``batch_warp.PARITY_TOLERANCE_M`` of the
  serial path over a control period. Needs the ``gpu`` extra (``make install-gpu``).

``make(robot, arms, backend="auto")`` takes ``warp`` where Warp finds a CUDA device and ``cpu``
otherwise. Each call names the arms it acts on (``arms``: indices; None for all); an arm that a
call leaves out keeps its state, so a vector environment resets some arms while the others run.
"""

import abc
from collections.abc import Sequence
import importlib.util
import os

import mujoco
from mujoco import rollout
import numpy as np

from softbench.robots import base
from softbench.robots import chain

BACKENDS = ("auto", "cpu", "warp")
POSE_SIZE = 6  # Tip position (m) and unit orientation vector of one module.
STATE_SPEC = mujoco.mjtState.mjSTATE_FULLPHYSICS  # The states ``states`` and ``set_states`` take.
ROW_SPEC = mujoco.mjtState.mjSTATE_INTEGRATION  # What ``mujoco.batch`` keeps of each arm.

Arms = Sequence[int] | np.ndarray | None


class ArmBatch(abc.ABC):
  """``num_arms`` arms of ``robot``, each at rest until its first ``hold``.

  Attributes:
    robot: the robot (faults included: they are in its MJCF).
    num_arms: how many arms the batch steps.
    steps_per_period: MuJoCo steps in one control period.
  """

  def __init__(self, robot: base.SoftArm, num_arms: int, model: mujoco.MjModel | None = None):
    """``model``: the robot's compiled model (default ``robot.compile()``), e.g. a copy of an
    environment's."""
    if isinstance(num_arms, bool) or not isinstance(num_arms, int | np.integer) or num_arms < 1:
      raise ValueError(f"the number of arms must be a positive integer, got {num_arms!r}")
    model = model if model is not None else robot.compile()
    self.model = model
    self.robot = robot
    self.num_arms = int(num_arms)
    self.steps_per_period = int(round(robot.control_timestep / model.opt.timestep))
    # The map as stored in the MJCF, exactly as SoftArmPhysics.set_action reads it.
    self._action_map = model.numeric(base.ACTION_MAP_NAME).data.reshape(-1, 4).copy()
    self._sites = np.array(
      [model.site(chain.tip_site_name(k)).id for k in range(1, robot.num_modules + 1)]
    )

  @property
  def state_size(self) -> int:
    """Entries of a full physics state (``STATE_SPEC``)."""
    return mujoco.mj_stateSize(self.model, STATE_SPEC)

  def arm_indices(self, arms: Arms) -> np.ndarray:
    """``arms`` as an int array of distinct indices (every arm for None).

    Raises:
      ValueError: an index out of range, repeated, or not an integer (one line).
    """
    if arms is None:
      return np.arange(self.num_arms)
    indices = np.asarray(arms)
    if indices.ndim != 1 or (indices.size and indices.dtype.kind not in "iu"):
      raise ValueError(f"arms must be a 1-D sequence of integer indices, got {arms!r}")
    indices = indices.astype(np.int64)
    if indices.size and (indices.min() < 0 or indices.max() >= self.num_arms):
      raise ValueError(f"arm indices must lie in [0, {self.num_arms}), got {indices.tolist()}")
    if len(np.unique(indices)) != len(indices):
      raise ValueError(f"arm indices must be distinct, got {indices.tolist()}")
    return indices

  def controls(self, actions: np.ndarray, count: int) -> np.ndarray:
    """The controls (count, num_actuators) of ``count`` arms' actions in [-1, 1].

    Raises:
      ValueError: a wrong shape, or an entry NaN, infinite or outside [-1, 1] (one line).
    """
    actions = base.checked_actions(actions, (count, self.robot.action_dim), "actions")
    return base.action_to_ctrl(self._action_map, actions)

  @abc.abstractmethod
  def reset(self, arms: Arms = None) -> None:
    """Puts ``arms`` at rest (reference configuration, zero velocity, time 0)."""

  @abc.abstractmethod
  def hold(self, actions: np.ndarray, arms: Arms = None) -> None:
    """Each of ``arms`` holds its row of ``actions`` (len(arms), action_dim) for one control
    period.

    Raises:
      ValueError: bad actions or arms (one line).
      FloatingPointError: the simulation of an arm became unstable.
    """

  @abc.abstractmethod
  def poses(self, arms: Arms = None) -> np.ndarray:
    """(len(arms), num_modules, 6): every module's tip position (m) and orientation vector."""

  def set_time(self, time: float, arms: Arms = None) -> None:
    """Sets the simulated time (s) of ``arms`` (dynamics do not depend on it)."""

  def close(self) -> None:
    """Frees the batch's threads or device memory."""

  def __enter__(self) -> "ArmBatch":
    return self

  def __exit__(self, *exc) -> None:
    self.close()


def _thread_count(threads: int | None, num_arms: int) -> int:
  threads = (os.cpu_count() or 1) if threads is None else threads
  if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
    raise ValueError(f"threads must be a positive integer, got {threads!r}")
  return min(threads, num_arms)


class CpuArmBatch(ArmBatch):
  """The ``cpu`` backend: ``mujoco.batch.Batch`` on ``threads`` threads (all cores if None)."""

  def __init__(
    self,
    robot: base.SoftArm,
    num_arms: int,
    threads: int | None = None,
    model: mujoco.MjModel | None = None,
  ):
    from mujoco import batch  # MuJoCo 4 (physics v1); the old stack has no batch module.

    super().__init__(robot, num_arms, model)
    threads = _thread_count(threads, self.num_arms)
    self._batch = batch.Batch(self.model, self.num_arms, nthread=threads)
    self._ctrl = self._batch.bind("ctrl")
    self._time = self._batch.bind("time")
    self._site_xpos = self._batch.bind("site_xpos")
    self._site_xmat = self._batch.bind("site_xmat")
    self._scratch = mujoco.MjData(self.model)
    self._bad_acceleration = int(mujoco.mjtWarning.mjWARN_BADQACC)
    self.reset()

  def reset(self, arms: Arms = None) -> None:
    indices = self.arm_indices(arms)
    self._batch.reset(indices, stage=mujoco.mjtStage.mjSTAGE_POS)

  def hold(self, actions: np.ndarray, arms: Arms = None) -> None:
    indices = self.arm_indices(arms)
    self._ctrl[indices] = self.controls(actions, len(indices))
    self._batch.step(indices, self.steps_per_period, stage=mujoco.mjtStage.mjSTAGE_POS)
    # MuJoCo resets a diverging simulation to the rest state and counts a warning.
    diverged = self._batch.warning[indices, self._bad_acceleration, 0] > 0
    if np.any(diverged):
      raise FloatingPointError(
        f"{self.robot.name}: simulation unstable in arm {int(indices[np.argmax(diverged)])}"
      )

  def poses(self, arms: Arms = None) -> np.ndarray:
    indices = self.arm_indices(arms)
    poses = np.empty((len(indices), len(self._sites), POSE_SIZE))
    poses[..., :3] = self._site_xpos[indices][:, self._sites]
    poses[..., 3:] = self._site_xmat[indices][:, self._sites].reshape(-1, len(self._sites), 3, 3)[
      ..., 2
    ]
    return poses

  def set_time(self, time: float, arms: Arms = None) -> None:
    self._time[self.arm_indices(arms)] = time

  def states(self, arms: Arms = None) -> np.ndarray:
    """(len(arms), state_size): full physics states (``mjSTATE_FULLPHYSICS``)."""
    rows = self._batch.state[self.arm_indices(arms)]
    states = np.empty((len(rows), self.state_size))
    for row, state in zip(rows, states):
      mujoco.mj_extractState(self.model, row, ROW_SPEC, state, STATE_SPEC)
    return states

  def set_states(self, states: np.ndarray, arms: Arms = None) -> None:
    """Puts ``arms`` in full physics states (len(arms), state_size), as ``states`` gives them."""
    indices = self.arm_indices(arms)
    states = np.asarray(states, dtype=np.float64).reshape(len(indices), self.state_size)
    for index, state in zip(indices, states):
      mujoco.mj_resetData(self.model, self._scratch)
      mujoco.mj_setState(self.model, self._scratch, state, STATE_SPEC)
      mujoco.mj_getState(self.model, self._scratch, self._batch.state[index], ROW_SPEC)
    self._batch.forward(indices, stage=mujoco.mjtStage.mjSTAGE_POS)

  def close(self) -> None:
    self._batch = None


class RolloutArmBatch(ArmBatch):
  """The ``cpu`` backend on MuJoCo 3: full physics states advanced by ``mujoco.rollout`` on a
  persistent thread pool of ``threads`` threads (all cores if None)."""

  def __init__(
    self,
    robot: base.SoftArm,
    num_arms: int,
    threads: int | None = None,
    model: mujoco.MjModel | None = None,
  ):
    super().__init__(robot, num_arms, model)
    threads = _thread_count(threads, self.num_arms)
    self._runner = rollout.Rollout(nthread=threads)
    self._datas = [mujoco.MjData(self.model) for _ in range(threads)]
    self._scratch = mujoco.MjData(self.model)
    self._rest = np.empty(self.state_size)
    mujoco.mj_getState(self.model, self._scratch, self._rest, STATE_SPEC)
    self._states = np.tile(self._rest, (self.num_arms, 1))

  def reset(self, arms: Arms = None) -> None:
    self._states[self.arm_indices(arms)] = self._rest

  def hold(self, actions: np.ndarray, arms: Arms = None) -> None:
    indices = self.arm_indices(arms)
    controls = self.controls(actions, len(indices))
    trajectory = np.empty((len(indices), self.steps_per_period, self.state_size))
    self._runner.rollout(
      [self.model] * len(indices),
      self._datas,
      self._states[indices],
      controls[:, None],
      nstep=self.steps_per_period,
      state=trajectory,
    )
    self._states[indices] = trajectory[:, -1]
    # MuJoCo resets a diverging simulation to the rest state and counts a warning.
    bad_acceleration = mujoco.mjtWarning.mjWARN_BADQACC
    diverged = any(data.warning[bad_acceleration].number for data in self._datas)
    if diverged or not np.all(np.isfinite(trajectory[:, -1])):
      raise FloatingPointError(f"{self.robot.name}: simulation unstable")

  def poses(self, arms: Arms = None) -> np.ndarray:
    states = self._states[self.arm_indices(arms)]
    return poses_of_states(self.model, self._scratch, self._sites, states)

  def set_time(self, time: float, arms: Arms = None) -> None:
    self._states[self.arm_indices(arms), 0] = time  # Time leads a full physics state.

  def states(self, arms: Arms = None) -> np.ndarray:
    """(len(arms), state_size): full physics states (``mjSTATE_FULLPHYSICS``)."""
    return self._states[self.arm_indices(arms)].copy()

  def set_states(self, states: np.ndarray, arms: Arms = None) -> None:
    """Puts ``arms`` in full physics states (len(arms), state_size), as ``states`` gives them."""
    indices = self.arm_indices(arms)
    self._states[indices] = np.asarray(states, np.float64).reshape(len(indices), self.state_size)

  def close(self) -> None:
    self._runner.close()


def poses_of_states(
  model: mujoco.MjModel, data: mujoco.MjData, sites: np.ndarray, states: np.ndarray
) -> np.ndarray:
  """(len(states), len(sites), 6): the tip sites' positions (m) and z-axes in full physics
  states (``STATE_SPEC``), each set in ``data`` in turn."""
  poses = np.empty((len(states), len(sites), POSE_SIZE))
  for pose, state in zip(poses, states):
    mujoco.mj_setState(model, data, state, STATE_SPEC)
    mujoco.mj_kinematics(model, data)
    pose[:, :3] = data.site_xpos[sites]
    pose[:, 3:] = data.site_xmat[sites].reshape(-1, 3, 3)[:, :, 2]
  return poses


def cpu(
  robot: base.SoftArm,
  num_arms: int,
  threads: int | None = None,
  model: mujoco.MjModel | None = None,
) -> CpuArmBatch | RolloutArmBatch:
  """The ``cpu`` backend of the installed MuJoCo (module docstring); ``model``: the robot's
  compiled model (default ``robot.compile()``), e.g. a copy of an environment's."""
  if importlib.util.find_spec("mujoco.batch") is None:
    return RolloutArmBatch(robot, num_arms, threads=threads, model=model)
  return CpuArmBatch(robot, num_arms, threads=threads, model=model)


def make(
  robot: base.SoftArm, num_arms: int, backend: str = "auto", threads: int | None = None
) -> ArmBatch:
  """A batch of ``num_arms`` arms of ``robot`` on ``backend`` (``BACKENDS``; module docstring).

  Raises:
    ValueError: an unknown backend, or ``warp`` where MuJoCo Warp is not installed (one line).
  """
  if backend not in BACKENDS:
    raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
  if backend == "auto":
    from softbench.robots import batch_warp

    backend = "warp" if batch_warp.cuda_available() else "cpu"
  if backend == "cpu":
    return cpu(robot, num_arms, threads=threads)
  from softbench.robots import batch_warp

  return batch_warp.WarpArmBatch(robot, num_arms)
