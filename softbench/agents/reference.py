"""``reference``: a model-based controller that plans on the simulator itself, to show how far the
learned controllers are from what the physics allows.

At every control step the agent copies the environment's full physics state (``mj_getState``; it
never writes to the environment) and, on its own copy of the model, looks for the action that,
held for one control period, brings the scored modules' tips to this step's target:

- residual: tip positions over the arm's length (dimensionless), plus, for 6-entry targets, the
  orientation vectors weighted by ``ORIENTATION_WEIGHT``;
- start: the previous action, with a forward-difference Jacobian (``action_dim + 1`` one-period
  simulations in one batch on MuJoCo's ``rollout`` thread pool);
- up to ``ITERATIONS`` damped least-squares steps, one simulation each, at most ``MAX_STEP`` per
  entry, inside [-1, 1] (entries pressed against a bound are held there and the others solved
  again). An accepted step (it lowers the residual) updates the Jacobian by Broyden's rule; a
  rejected one first refreshes the Jacobian by finite differences, then raises the damping;
- a pull towards zero action (``EFFORT``) that fades with the residual, so that from far away
  the arm takes the least-effort branch of a redundant target (reach) and, near the target, the
  solution is unbiased;
- stop when the residual is below ``TOLERANCE``;
- if it is still above ``RESTART_RESIDUAL`` (the target is far from where the previous action
  leads, as on ``babbling``, whose targets jump across the workspace every step, so that local
  steps from the previous action often stall), simulate the zero action and a batch of
  candidates, run up to ``RESTART_ITERATIONS`` more steps from the best of them and the local
  search's action, and keep whichever solution leaves the smaller residual. The candidates are
  ``RESTART_SAMPLES`` fixed random actions at the episode's first restart, then the
  ``RESTART_CANDIDATES`` actions whose simulated features lay nearest this step's goal among
  the episode's last ``MEMORY_SIZE`` simulations (unperturbed ones only). Smooth tracking
  converges without restarting.

The constants were chosen by measurement on tendon-3 reach (8 seeds), tendon-2 circle
(10 steps), pneumatic-433 circle and spiral and tendon-3 spiral (first 60-100 steps), and the
restart's on babbling. Every simulation starts from the same copied state, so the same state and
observation always give the same action, whatever the thread count, and whatever kernels
OpenBLAS picks for the CPU (the algebra is MuJoCo's, see ``_damped_least_squares``); the memory
starts empty at every ``reset``. Near the arms' bending limits the pose can depend roughly on the
action; there the agent may stop a few mm from a reach target.

Cost on a 2-core CPU: about 0.1 s per control step of tendon-3 (a 1000-step tracking episode in
about 2 minutes), 0.05 s on pneumatic-433; a control period of tendon-5 is 3x dearer to simulate.
Restarting makes a step dearer: on babbling's first 40 steps, with the 2 cores to itself,
0.63 s per step on tendon-3 and 0.29 s on pneumatic-433. Remembered candidates instead of the
64 samples at every restart cut this from 1.15 s and 0.43 s at the same accuracy: on 200
pneumatic-433 and 150 tendon-3 steps scored from the states of babbling's own path (where the
generating action reaches the target exactly), 54 and 13 steps missed by more than 0.1 mm,
against 55 and 15 with the samples.
"""

import copy
import os

import mujoco
import numpy as np

from softbench import profiles
from softbench.agents import base
from softbench.robots import base as robot_base
from softbench.robots import recorder

ITERATIONS = 6  # Most damped least-squares steps per control step (one simulation each).
TOLERANCE = 1e-4  # (arm lengths) Residual below which the agent acts without further steps.
FD_STEP = 1e-2  # (action units) Forward-difference step; smaller steps see the bending limits'
# roughness and stall reach targets near them.
DAMPING = 1e-3  # (arm lengths per action unit) Damping of the least-squares steps.
DAMPING_GROWTH = 10.0  # Factor on the damping after a rejected step with a fresh Jacobian.
MAX_STEP = 0.5  # (action units) Largest change of an action entry per step.
EFFORT = 0.1  # (arm lengths per action unit) Pull towards zero action at a large residual ...
EFFORT_SCALE = 0.1  # (arm lengths) ... scaled by min(1, residual / EFFORT_SCALE).
ORIENTATION_WEIGHT = 1.0  # (arm lengths per unit of orientation-vector error) 6-entry targets.
RESTART_RESIDUAL = 1e-2  # (arm lengths) Residual after the local search above which it restarts.
RESTART_SAMPLES = 64  # Random actions simulated to pick the restart's starting point; 16 left
# tendon-3 babbling at 4.1 mm mean error over its first 40 steps, 64 at 0.5 mm.
RESTART_ITERATIONS = 20  # Most damped least-squares steps from the restart's starting point.
RESTART_SEED = 0  # Seed of the fixed restart samples (the same every step and episode).
RESTART_CANDIDATES = 16  # Remembered actions, nearest the goal, simulated at a later restart;
# with 8, 55 of 200 on-path pneumatic-433 babbling steps missed by more than 0.1 mm, with 16 54.
MEMORY_SIZE = 4096  # (simulations) The latest ones an episode remembers (about 40 babbling steps).


class ReferenceAgent(base.Agent):
  """Damped least-squares control through one-period simulations of the bound physics."""

  uses_simulator = True

  def __init__(self, robot: robot_base.SoftArm, seed: int, threads: int | None = None):
    super().__init__(robot, seed)
    self._threads = threads or os.cpu_count() or 1
    self._physics = None
    self._scored = np.arange(robot.num_modules)
    self._restart_starts = np.vstack(
      [
        np.zeros(robot.action_dim),
        np.random.default_rng(RESTART_SEED).uniform(-1.0, 1.0, (RESTART_SAMPLES, robot.action_dim)),
      ]
    )
    self._forget()

  def bind(self, physics) -> None:
    self._physics = physics
    self._recorder = recorder.PoseRecorder(
      self.robot, self._threads, model=copy.copy(physics.model.ptr)
    )
    self._state = np.empty(self._recorder.state_size)

  def reset(self, episode: base.EpisodeInfo) -> None:
    self._scored = np.array(episode.scored_modules, dtype=int) - 1
    self._forget()

  def _forget(self) -> None:
    """Empties the memory of simulated (action, features) pairs, as at the start of an episode."""
    self._memory_actions = np.empty((0, self.robot.action_dim))
    self._memory_features = None
    self._restarted = False

  def episode_state(self) -> dict[str, np.ndarray]:
    """The memory of simulated pairs and whether the episode has restarted (a step of babbling
    takes seconds: its episodes resume mid-way)."""
    state = {"memory_actions": self._memory_actions, "restarted": np.asarray(self._restarted)}
    if self._memory_features is not None:
      state["memory_features"] = self._memory_features
    return state

  def restore_episode_state(self, state: dict[str, np.ndarray]) -> None:
    self._memory_actions = np.array(state["memory_actions"], dtype=float)
    features = state.get("memory_features")
    self._memory_features = None if features is None else np.array(features, dtype=float)
    self._restarted = bool(state["restarted"])

  def _simulate(self, actions: np.ndarray, orientation: bool, remember: bool = True) -> np.ndarray:
    """(batch, features) after holding each action (batch, action_dim) for one control period:
    scored tip positions over the arm length, then weighted orientation vectors."""
    poses, _ = self._recorder.record(
      actions[:, None], np.broadcast_to(self._state, (len(actions), len(self._state)))
    )
    scored = poses[:, -1, self._scored]
    features = [scored[..., :3].reshape(len(actions), -1) / self.robot.length]
    if orientation:
      features.append(ORIENTATION_WEIGHT * scored[..., 3:].reshape(len(actions), -1))
    features = np.concatenate(features, axis=1)
    if remember:
      self._remember(actions, features)
    return features

  def _remember(self, actions: np.ndarray, features: np.ndarray) -> None:
    """Adds simulated (action, features) pairs to the episode's memory, keeping the latest
    ``MEMORY_SIZE``."""
    if self._memory_features is None or self._memory_features.shape[1] != features.shape[1]:
      self._memory_features = np.empty((0, features.shape[1]))  # The episode's first call.
      self._memory_actions = np.empty((0, self.robot.action_dim))
    self._memory_actions = np.concatenate([self._memory_actions, actions])[-MEMORY_SIZE:]
    self._memory_features = np.concatenate([self._memory_features, features])[-MEMORY_SIZE:]

  def _linearise(self, action: np.ndarray, orientation: bool) -> tuple[np.ndarray, np.ndarray]:
    """Forward-difference Jacobian (features, action_dim) and the features at ``action``."""
    steps = np.where(action + FD_STEP <= 1.0, FD_STEP, -FD_STEP)
    # Only the unperturbed action is remembered: its perturbations would crowd the nearest.
    features = self._simulate(
      np.vstack([action, action + np.diag(steps)]), orientation, remember=False
    )
    self._remember(action[None], features[:1])
    return ((features[1:] - features[0]) / steps[:, None]).T, features[0]

  def _step(
    self, jacobian: np.ndarray, residual: np.ndarray, damping: float, action: np.ndarray
  ) -> np.ndarray:
    """The next action: argmin |J d - r|^2 + damping^2 |d|^2 + effort^2 |a + d|^2 over the
    entries not pressed against a bound, shortened to ``MAX_STEP`` and clipped to [-1, 1]."""
    effort = EFFORT * min(1.0, mujoco.mju_norm(residual) / EFFORT_SCALE)
    free = np.ones(len(action), dtype=bool)
    step = np.zeros(len(action))
    for _ in range(len(action)):
      step[:] = 0.0
      step[free] = _damped_least_squares(
        jacobian[:, free], residual, damping**2 + effort**2, effort**2 * action[free]
      )
      pressed = free & (((action >= 1.0) & (step > 0)) | ((action <= -1.0) & (step < 0)))
      if not pressed.any() or pressed.all():
        break
      free &= ~pressed
    step *= min(1.0, MAX_STEP / max(np.abs(step).max(), 1e-12))
    return np.clip(action + step, -1.0, 1.0)

  def act(self, observation: dict) -> np.ndarray:
    if self._physics is None:
      raise RuntimeError("the reference agent needs bind(physics) before acting")
    physics = self._physics
    mujoco.mj_getState(physics.model.ptr, physics.data.ptr, self._state, recorder.STATE_SPEC)
    target = np.asarray(observation["target"], dtype=float)
    orientation = target.shape[-1] == 6
    goal = [target[:, :3].ravel() / self.robot.length]
    if orientation:
      goal.append(ORIENTATION_WEIGHT * target[:, 3:].ravel())
    goal = np.concatenate(goal)

    previous = np.clip(np.asarray(observation["previous_action"], dtype=float), -1.0, 1.0)
    action, residual = self._search(goal, previous, orientation, ITERATIONS)
    if residual > RESTART_RESIDUAL:
      action = self._restart(goal, action, residual, orientation)
    return action

  def _restart(
    self, goal: np.ndarray, action: np.ndarray, residual: float, orientation: bool
  ) -> np.ndarray:
    """The better of ``action`` (residual ``residual``) and a search of up to
    ``RESTART_ITERATIONS`` steps from the best of: ``action``, the zero action and either the
    fixed sampled actions (the episode's first restart) or the ``RESTART_CANDIDATES``
    remembered actions whose features lay nearest ``goal``, all simulated from this state."""
    if not self._restarted:
      candidates = self._restart_starts
      self._restarted = True
    else:
      distances = np.linalg.norm(goal - self._memory_features, axis=1)
      nearest = self._memory_actions[np.argsort(distances, kind="stable")[:RESTART_CANDIDATES]]
      candidates = np.vstack([self._restart_starts[:1], nearest])
    distances = np.linalg.norm(goal - self._simulate(candidates, orientation), axis=1)
    start = candidates[np.argmin(distances)] if distances.min() < residual else action
    restarted, restarted_residual = self._search(goal, start, orientation, RESTART_ITERATIONS)
    return restarted if restarted_residual < residual else action

  def _search(
    self, goal: np.ndarray, action: np.ndarray, orientation: bool, iterations: int
  ) -> tuple[np.ndarray, float]:
    """Up to ``iterations`` damped least-squares steps from ``action`` towards ``goal``: the
    action reached and the norm of its residual (arm lengths)."""
    jacobian, feature = self._linearise(action, orientation)
    fresh = True  # Whether the Jacobian is a finite-difference one at ``action``.
    residual = goal - feature
    damping = DAMPING
    for _ in range(iterations):
      if mujoco.mju_norm(residual) < TOLERANCE:
        break
      candidate = self._step(jacobian, residual, damping, action)
      candidate_feature = self._simulate(candidate[None], orientation)[0]
      if mujoco.mju_norm(goal - candidate_feature) < mujoco.mju_norm(residual):
        step = candidate - action
        predicted_change = np.empty(len(feature))
        mujoco.mju_mulMatVec(predicted_change, jacobian, step)
        jacobian = jacobian + np.outer(
          candidate_feature - feature - predicted_change, step
        ) / mujoco.mju_dot(step, step)
        action, feature, residual = candidate, candidate_feature, goal - candidate_feature
        fresh = False
      elif not fresh:
        jacobian, _ = self._linearise(action, orientation)
        fresh = True
      else:
        damping *= DAMPING_GROWTH
    return action, mujoco.mju_norm(residual)


def _damped_least_squares(
  jacobian: np.ndarray, residual: np.ndarray, regulariser: float, pull: np.ndarray
) -> np.ndarray:
  """The step d solving (J^T J + regulariser I) d = J^T residual - pull, by Cholesky.

  MuJoCo's own routines, not numpy's: numpy's products and solves run through OpenBLAS, which picks
  its kernels by CPU, and their last-bit differences decide some of babbling's restarts (the same
  tendon-3 step stalled 9 to 46 mm off with the AVX-512 kernels, 6 to 31 mm off with the SSE ones
  and converged with the AVX2 ones). MuJoCo's are the same code on every CPU, as the physics is.
  """
  size = jacobian.shape[1]
  normal = np.empty((size, size))
  mujoco.mju_mulMatTMat(normal, jacobian, jacobian)
  normal[np.diag_indices(size)] += regulariser
  right_hand_side = np.empty(size)
  mujoco.mju_mulMatTVec(right_hand_side, jacobian, residual)
  right_hand_side -= pull
  mujoco.mju_cholFactor(normal, 0.0)
  step = np.empty(size)
  mujoco.mju_cholSolve(step, normal, right_hand_side)
  return step


def build(
  robot: robot_base.SoftArm, seed: int, profile: profiles.Profile, show_progress: bool = False
) -> base.Agent:
  del profile, show_progress  # Nothing to train: the agent plans on the simulator.
  return ReferenceAgent(robot, seed)
