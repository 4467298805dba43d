"""Target completion's parts on their own (``softbench.agents.completion``): the nearest babbling
pose, the refinement through a forward model and the correction from the measured error. Every
learned agent's completion is tested in ``test_adaptive`` (``TestCompletion``)."""

import json

import numpy as np
import pytest
import torch

from softbench import cli
from softbench import suite
from softbench.agents import completion
from softbench.data import dataset
from softbench.data import splits
from softbench.suite import trajectories

ARM_LENGTH = 0.3  # (m)
TIMESTEP = 0.5  # (s)
MODULES, ACTIONS = 3, 4


def random_candidates(count=500, seed=0) -> completion.Candidates:
  rng = np.random.default_rng(seed)
  poses = rng.uniform(-ARM_LENGTH, ARM_LENGTH, (count, MODULES, 6))
  poses[..., 3:] /= np.linalg.norm(poses[..., 3:], axis=-1, keepdims=True)
  return completion.Candidates(poses, rng.uniform(-1, 1, (count, ACTIONS)))


def linear_arm(seed=0):
  """A differentiable stand-in for the forward models: every module's pose is an affine function
  of the held action (orientation (0, 0, -1) plus a tilt), whatever the start."""
  generator = torch.Generator().manual_seed(seed)
  weights = 0.05 * torch.randn(MODULES, 6, ACTIONS, generator=generator)
  rest = torch.zeros(MODULES, 6)
  rest[:, 2] = -torch.arange(1, MODULES + 1) * ARM_LENGTH / MODULES
  rest[:, 5] = -1.0

  def predict(action, previous_poses, poses, steps):
    return rest + weights @ action

  return predict


def completer(candidates=None, predict=None) -> completion.Completer:
  return completion.Completer(
    lambda: candidates or random_candidates(),
    predict or linear_arm(),
    ARM_LENGTH,
    TIMESTEP,
  )


def complete(completer, goal, given, refine=True, poses=None, active=None):
  poses = np.zeros((MODULES, 6)) if poses is None else poses
  active = np.ones(ACTIONS, bool) if active is None else active
  return completer.complete(goal, given, poses, poses, active, refine=refine)


@pytest.mark.parametrize(
  "given", [trajectories.Given((2,), orientation=False), trajectories.Given((1, 3))]
)
def test_the_nearest_pose_is_the_brute_force_nearest_in_arm_lengths(given):
  candidates = random_candidates()
  rng = np.random.default_rng(1)
  for _ in range(20):
    goal = rng.uniform(-ARM_LENGTH, ARM_LENGTH, (len(given.modules), given.size))
    target = complete(completer(candidates), goal, given, refine=False)
    scale = np.ones(given.size)
    scale[:3] = 1 / ARM_LENGTH
    distances = np.linalg.norm(
      ((given.part(candidates.poses) - goal) * scale).reshape(len(candidates.poses), -1), axis=1
    )
    expected = candidates.poses[np.argmin(distances)].copy()
    expected[given.indices, : given.size] = goal
    np.testing.assert_array_equal(target, expected)


def test_candidates_are_the_training_splits_reached_poses_with_their_actions(babbled_datasets):
  (folder,) = babbled_datasets("tendon-2").iterdir()
  data = dataset.read(folder)
  candidates = completion.Candidates.from_dataset(data)
  pieces = splits.split_pieces(data.episode_lengths)["train"]
  assert len(candidates.poses) == len(candidates.actions) == sum(p.samples for p in pieces)
  poses, actions = pieces[0].recording(data)
  np.testing.assert_array_equal(candidates.poses[0], poses[1])  # After holding actions[0].
  np.testing.assert_array_equal(candidates.actions[0], actions[0])


def test_refinement_meets_a_reachable_goal_through_the_model():
  predict = linear_arm()
  wanted_action = torch.tensor([0.3, -0.5, 0.2, 0.6])
  goal = predict(wanted_action, None, None, 1)[1:2, :3].numpy().astype(float)
  given = trajectories.Given((2,), orientation=False)
  target = complete(completer(predict=predict), goal, given)
  np.testing.assert_array_equal(target[1, :3], goal[0])
  # The other modules' targets are where the model puts them for an action that meets the goal.
  refined = completer(predict=predict)
  refined.complete(goal, given, np.zeros((MODULES, 6)), np.zeros((MODULES, 6)), np.ones(4, bool))
  predicted = predict(torch.as_tensor(refined._action, dtype=torch.float32), None, None, 1)
  assert np.linalg.norm(predicted[1, :3].numpy() - goal[0]) < 1e-3 * ARM_LENGTH


def test_refinement_never_raises_the_models_error_and_keeps_inactive_actions_at_zero():
  predict = linear_arm(seed=3)
  given = trajectories.Given((3,), orientation=False)
  goal = np.array([[0.5, 0.5, -0.1]])  # Out of reach: the error stays, but must not grow.
  active = np.array([True, True, False, False])
  found = completer(predict=predict)
  complete(found, goal, given, active=active)
  refined = found._action
  assert np.all(refined[~active] == 0.0) and np.all(np.abs(refined) <= 1.0)
  nearest = completer(predict=predict)
  complete(nearest, goal, given, refine=False, active=active)
  start = torch.as_tensor(nearest._action * active, dtype=torch.float32)
  error = lambda action: np.linalg.norm(
    predict(torch.as_tensor(action, dtype=torch.float32), None, None, 1)[2, :3].numpy() - goal[0]
  )
  assert error(refined) <= error(start.numpy())


def test_a_still_goal_is_corrected_by_the_integrated_measured_error():
  given = trajectories.Given((2,), orientation=False)
  goal = np.array([[0.05, 0.0, -0.2]])
  found = completer()
  measured = np.zeros((MODULES, 6))
  measured[1, :3] = goal[0] - [0.01, 0.0, 0.0]  # 10 mm short in x, every step.
  hold_steps = int(np.ceil(completion.HOLD_SECONDS / TIMESTEP))
  gain = TIMESTEP / completion.CORRECTION_TIME_CONSTANT_S
  for step in range(hold_steps + 3):
    target = complete(found, goal, given, refine=False, poses=measured)
    corrections = max(0, step - hold_steps + 1)
    np.testing.assert_allclose(target[1, :3], goal[0] + [0.01 * gain * corrections, 0, 0])
  # A new goal starts without correction; the correction is bounded.
  np.testing.assert_array_equal(
    complete(found, goal + 0.01, given, refine=False)[1, :3], goal[0] + 0.01
  )
  far = np.zeros((MODULES, 6))
  far[1, :3] = goal[0] - [10.0, 0, 0]
  for _ in range(hold_steps + 50):
    target = complete(found, goal, given, refine=False, poses=far)
  limit = completion.MAX_CORRECTION_ARM_LENGTHS * ARM_LENGTH
  assert np.linalg.norm(target[1, :3] - goal[0]) == pytest.approx(limit)


def test_a_masked_custom_run_is_completed_and_the_record_says_how(tmp_path, babbled_home, capsys):
  babbled_home(tmp_path / "home")
  circle = suite.load("tendon-2", "circle", seed=0, length=3)
  rows = np.array([circle.task.targets_at(step)[1, :3] for step in range(3)])
  trajectory = tmp_path / "module-2.csv"
  np.savetxt(trajectory, rows, delimiter=",")
  argv = ["run", "--task", "custom", "--trajectory", str(trajectory), "--robot", "tendon-2"]
  argv += ["--agent", "mlp", "--profile", "tiny", "--seeds", "1", "--results", str(tmp_path)]
  assert cli.main([*argv, "--given", "2:position"]) == 0
  (path,) = tmp_path.glob("*.json")
  record = json.loads(path.read_text())
  assert (record["given"], record["helpers"], record["scored_modules"]) == (
    "2:position",
    "complete",
    [2],
  )
  assert cli.main([*argv, "--given", "2"]) == cli.EXIT_USAGE  # The file gives no orientation.
  assert "must have shape (steps, 6)" in capsys.readouterr().err
  circle_argv = ["run", "--task", "circle", "--robot", "tendon-2", "--agent", "mlp"]
  assert cli.main([*circle_argv, "--given", "2", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  assert "--given goes with --task custom" in capsys.readouterr().err


def test_without_measured_feedback_a_still_goal_is_not_corrected():
  given = trajectories.Given((2,), orientation=False)
  goal = np.array([[0.05, 0.0, -0.2]])
  found = completer()
  measured = np.zeros((MODULES, 6))
  measured[1, :3] = goal[0] - [0.01, 0.0, 0.0]
  for _ in range(int(np.ceil(completion.HOLD_SECONDS / TIMESTEP)) + 3):
    target = found.complete(goal, given, measured, measured, np.ones(ACTIONS, bool), False, False)
    np.testing.assert_array_equal(target[1, :3], goal[0])
