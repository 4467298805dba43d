"""Target completion: a whole-arm pose target from a goal that gives only part of it.

A learned inverse model maps target poses of every module to actions. A task that gives less
(``reach``: one module's position; a ``custom`` trajectory with a mask: some modules, with or
without orientations) leaves the rest to the agent, which completes it from what it learned:

1. **Nearest babbling pose.** Of the poses its babbling dataset's training split reached, the one
   whose given part lies nearest the goal (``scipy.spatial.cKDTree``; positions in arm lengths,
   orientation vectors as they are), with the action that produced it.
2. **Refinement through its own frozen forward models** (mode ``complete``). Starting from that
   action, a few damped Gauss-Newton steps move the action, held for ``HOLD_SECONDS`` from the
   arm's measured poses, until the predicted given part meets the goal. The predicted poses of
   every module are the target; the given part is the goal itself.
3. **From the measured error, during the episode.** While a goal stays still (reach), once the
   arm has had ``HOLD_SECONDS`` to settle, the measured position error of each given module is
   integrated into the goal that stages 1 and 2 complete (time constant
   ``CORRECTION_TIME_CONSTANT_S``, at most ``MAX_CORRECTION_ARM_LENGTHS``), so that a bias of the
   forward model does not stay as a steady error. The refinement runs again once per
   ``HOLD_SECONDS`` (and when the active modules change), from the last action found; in between
   the corrected goal is written into the last completed pose. A goal that moves (a trajectory)
   is completed afresh every step, without correction.

Mode ``nearest`` stops after stage 1 (with the same correction), for comparison. Modules switched
off (adaptive activation) keep a zero action in the refinement, so their targets are where the
model predicts they will be carried.
"""

from collections.abc import Callable
import dataclasses

import numpy as np
from scipy import spatial
import torch

from softbench.data import dataset
from softbench.data import splits
from softbench.suite import trajectories

HOLD_SECONDS = 2.0  # (s) How long the refinement holds an action, and how long a still goal waits
# before its correction starts; longer than every registered robot's settling time (tendon-5
# 0.72 s, pneumatic-433 1.39 s).
REFINEMENT_STEPS = 5  # Damped Gauss-Newton steps on the action for a new goal.
WARM_REFINEMENT_STEPS = 1  # Steps for a corrected goal, from the last action found.
INITIAL_DAMPING = 1e-2  # Levenberg-Marquardt damping of J^T J (residuals in arm lengths and
# orientation units, actions in [-1, 1]); multiplied by DAMPING_FACTOR after a step that fails
# to lower the error (up to DAMPING_TRIES times per step), divided by it after one that does.
DAMPING_FACTOR = 10.0
DAMPING_TRIES = 4
CORRECTION_TIME_CONSTANT_S = 2.0  # (s) Of the integral correction of a still goal.
MAX_CORRECTION_ARM_LENGTHS = 0.25  # Largest correction of one module's goal position.
POSITION = slice(0, 3)


@dataclasses.dataclass(frozen=True, eq=False)
class Candidates:
  """Poses the arm reached in the training split of its babbling, each with its action.

  Attributes:
    poses: (n, num_modules, 6) the pose at the end of each control period.
    actions: (n, action_dim) the action held during that period.
  """

  poses: np.ndarray
  actions: np.ndarray

  @classmethod
  def from_dataset(cls, data: dataset.Dataset) -> "Candidates":
    """The training split's reached poses of ``data`` (``softbench.data.splits``)."""
    recordings = [
      piece.recording(data) for piece in splits.split_pieces(data.episode_lengths)["train"]
    ]
    return cls(
      np.concatenate([poses[1:] for poses, _ in recordings]),
      np.concatenate([actions for _, actions in recordings]),
    )


class Completer:
  """Completes partial targets for one agent, one episode at a time (module docstring).

  Args:
    candidates: Builds the babbling candidates when first needed (it may collect the dataset).
    predict: Every module's predicted poses (num_modules, 6), a differentiable function of the
      action (action_dim,) held for ``steps`` control steps from the measured previous and
      current poses.
    arm_length: (m) The arm's length, the unit of positions in the nearest-pose search.
    control_timestep: (s) Time between two actions.
  """

  def __init__(
    self,
    candidates: Callable[[], Candidates],
    predict: Callable[[torch.Tensor, np.ndarray, np.ndarray, int], torch.Tensor],
    arm_length: float,
    control_timestep: float,
  ):
    self._make_candidates = candidates
    self._candidates = None
    self._trees: dict[trajectories.Given, spatial.cKDTree] = {}
    self._predict = predict
    self._arm_length = arm_length
    self._hold_steps = max(1, int(np.ceil(HOLD_SECONDS / control_timestep)))
    self._gain = min(1.0, control_timestep / CORRECTION_TIME_CONSTANT_S)
    self.reset()

  def reset(self) -> None:
    """Forgets the episode: the goal, its correction and the last action found."""
    self._goal = None
    self._still_steps = 0
    self._correction = None
    self._action = None
    self._pose = None  # The completed pose before the goal's own part is written in.
    self._active = None  # The action entries the last refinement could move.

  def complete(
    self,
    goal: np.ndarray,
    given: trajectories.Given,
    previous_poses: np.ndarray,
    poses: np.ndarray,
    active_actions: np.ndarray,
    refine: bool = True,
    correct: bool = True,
  ) -> np.ndarray:
    """The whole-arm target (num_modules, 6) for ``goal`` (len(given.modules), given.size), the
    arm now at ``poses`` after ``previous_poses``; entries of the action outside
    ``active_actions`` (a boolean mask) stay zero. ``correct``: whether a still goal is corrected
    from the measured error (stage 3; not when the agent acts without measured feedback)."""
    goal = np.asarray(goal, dtype=float)
    if self._goal is None or not np.array_equal(goal, self._goal):
      self._goal, self._still_steps = goal.copy(), 0
      self._correction = np.zeros((len(given.modules), 3))
    else:
      self._still_steps += 1
    if correct and self._still_steps >= self._hold_steps:
      error = goal[:, POSITION] - given.part(poses)[:, POSITION]
      self._correction = _clip_norms(
        self._correction + self._gain * error, MAX_CORRECTION_ARM_LENGTHS * self._arm_length
      )
    corrected = goal.copy()
    corrected[:, POSITION] += self._correction
    new_goal = self._still_steps == 0
    if new_goal or not refine:
      self._pose, self._action = self._nearest(corrected, given)
    mask_changed = self._active is None or not np.array_equal(active_actions, self._active)
    if refine and (new_goal or mask_changed or self._still_steps % self._hold_steps == 0):
      steps = REFINEMENT_STEPS if new_goal else WARM_REFINEMENT_STEPS
      self._action = self._refine(corrected, given, previous_poses, poses, active_actions, steps)
      with torch.no_grad():
        pose = self._predict(
          torch.as_tensor(self._action, dtype=torch.float32),
          previous_poses,
          poses,
          self._hold_steps,
        )
      self._pose = pose.numpy().astype(float)
      self._pose[:, 3:] /= np.maximum(
        np.linalg.norm(self._pose[:, 3:], axis=-1, keepdims=True), 1e-9
      )
    self._active = np.array(active_actions, dtype=bool)
    target = np.array(self._pose, dtype=float)
    target[given.indices, : given.size] = corrected
    return target

  def _nearest(self, goal: np.ndarray, given: trajectories.Given) -> tuple[np.ndarray, np.ndarray]:
    """The candidate pose whose given part lies nearest ``goal``, and its action."""
    if self._candidates is None:
      self._candidates = self._make_candidates()
    if given not in self._trees:
      self._trees[given] = spatial.cKDTree(self._search_keys(given.part(self._candidates.poses)))
    _, index = self._trees[given].query(self._search_keys(goal[None])[0])
    return self._candidates.poses[index].copy(), self._candidates.actions[index].copy()

  def _search_keys(self, parts: np.ndarray) -> np.ndarray:
    """Given parts (n, modules, size) as k-d tree points: positions in arm lengths."""
    scaled = np.array(parts, dtype=float)
    scaled[..., POSITION] /= self._arm_length
    return scaled.reshape(len(scaled), -1)

  def _refine(
    self,
    goal: np.ndarray,
    given: trajectories.Given,
    previous_poses: np.ndarray,
    poses: np.ndarray,
    active_actions: np.ndarray,
    steps: int,
  ) -> np.ndarray:
    """The action after ``steps`` damped Gauss-Newton steps from the last one."""
    active = torch.as_tensor(active_actions, dtype=torch.float32)
    scale = torch.ones(given.size, dtype=torch.float32)
    scale[POSITION] = 1.0 / self._arm_length
    wanted = torch.as_tensor(goal, dtype=torch.float32) * scale

    def residual(action: torch.Tensor) -> torch.Tensor:
      predicted = self._predict(action * active, previous_poses, poses, self._hold_steps)
      return (predicted[given.indices, : given.size] * scale - wanted).reshape(-1)

    action = torch.as_tensor(self._action, dtype=torch.float32) * active
    damping = INITIAL_DAMPING
    for _ in range(steps):
      variable = action.clone().requires_grad_(True)
      error = residual(variable)
      jacobian = torch.stack(
        [torch.autograd.grad(entry, variable, retain_graph=True)[0] for entry in error]
      )
      with torch.no_grad():
        error, normal = error.detach(), jacobian.T @ jacobian
        for _ in range(DAMPING_TRIES):  # Levenberg-Marquardt: only a step that lowers the error.
          step = torch.linalg.solve(normal + damping * torch.eye(len(action)), jacobian.T @ error)
          tried = torch.clamp(action - step, -1.0, 1.0) * active
          if residual(tried).norm() < error.norm():
            action, damping = tried, damping / DAMPING_FACTOR
            break
          damping *= DAMPING_FACTOR
    return action.numpy().astype(float)


def _clip_norms(vectors: np.ndarray, limit: float) -> np.ndarray:
  """``vectors`` (n, 3), each scaled down to at most ``limit`` long."""
  norms = np.linalg.norm(vectors, axis=-1, keepdims=True)
  return vectors * np.minimum(1.0, limit / np.maximum(norms, 1e-12))
