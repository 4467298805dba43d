"""The closed loop feeds each step the error of the previous step of the same sequence."""

from typing import Any

import pytest
import torch
from torch import Tensor
from torch import nn

from smpl.forward_model import ForwardModel
from smpl.inverse import InverseModel
from smpl.inverse import InverseStep
from smpl.progressive import ProgressiveLSTM
from smpl.rollout import Rollout
from smpl.rollout import rollout
from smpl.windows import BabblingWindows

POSE, ACTION, STEPS, BATCH = 6, 2, 15, 3


class _ScriptedInverse(InverseModel):
  """Outputs t + 1 in every action component at step t, and records the inputs it receives."""

  def __init__(self) -> None:
    super().__init__()
    self.input_size, self.action_size = 2 * POSE + ACTION, ACTION
    self.received: list[Tensor] = []

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    steps = torch.arange(1, inputs.shape[1] + 1, dtype=inputs.dtype)
    actions = steps[None, :, None].expand(inputs.shape[0], -1, ACTION)
    return actions, inputs.new_zeros(())

  def initial_state(self, batch_size: int) -> int:
    return 0

  def step(self, inputs: Tensor, state: int) -> InverseStep:
    self.received.append(inputs)
    action = inputs.new_full((inputs.shape[0], ACTION), float(state + 1))
    return InverseStep(action, inputs.new_zeros(()), state + 1)


class _RecordingForwardModel(ForwardModel):
  """Predicts x'_{t+1} = x_t + sum(actuation_t) in every pose component; records its inputs."""

  def __init__(self) -> None:
    super().__init__(actuation_size=ACTION)
    self.calls: list[tuple[Tensor, Tensor, Tensor]] = []

  def step(
    self, previous_pose: Tensor, current_pose: Tensor, actuation: Tensor, state: Any
  ) -> tuple[Tensor, Any]:
    self.calls.append((previous_pose, current_pose, actuation))
    return current_pose + actuation.sum(dim=-1, keepdim=True), state


def _numbered_windows() -> BabblingWindows:
  """Pose x_i of sequence b is i + 1000 b in every component (poses[:, j] holds x_{j-1})."""
  pose_index = torch.arange(-1, STEPS + 1, dtype=torch.float32)
  sequence_offset = 1000.0 * torch.arange(BATCH, dtype=torch.float32)
  poses = (pose_index[None, :, None] + sequence_offset[:, None, None]).expand(
    BATCH, STEPS + 2, POSE
  )
  return BabblingWindows(
    poses.clone(), torch.zeros(BATCH, STEPS, ACTION), torch.zeros(BATCH, STEPS, 0)
  )


def _scripted_rollout() -> tuple[_ScriptedInverse, _RecordingForwardModel, Rollout]:
  """A rollout of the scripted inverse model through the recording forward model."""
  inverse, forward_model = _ScriptedInverse(), _RecordingForwardModel()
  return inverse, forward_model, rollout(inverse, _numbered_windows(), forward_model)


def test_each_step_reads_its_target_the_previous_steps_error_and_the_previous_action() -> None:
  inverse, _, result = _scripted_rollout()
  offset = 1000.0 * torch.arange(BATCH)[:, None]
  for t in range(STEPS):
    target, error, previous_action = inverse.received[t].split([POSE, POSE, ACTION], dim=-1)
    assert torch.equal(target, (t + 1 + offset).expand(BATCH, POSE))
    # e_t = x_t - x'_t, where x'_t = x_{t-1} + ACTION * t (step t-1 acted t): so 1 - ACTION t.
    expected_error = 0.0 if t == 0 else 1.0 - ACTION * t
    assert torch.equal(error, torch.full((BATCH, POSE), expected_error)), t
    assert torch.equal(previous_action, torch.full((BATCH, ACTION), float(t))), t
    assert torch.equal(result.errors[:, t], error)


def test_forward_model_sees_the_recorded_poses_and_the_action_of_the_same_step() -> None:
  inverse, forward_model, result = _scripted_rollout()
  offset = 1000.0 * torch.arange(BATCH)[:, None]
  assert len(forward_model.calls) == STEPS
  for t, (previous_pose, current_pose, actuation) in enumerate(forward_model.calls):
    assert torch.equal(previous_pose, (t - 1 + offset).expand(BATCH, POSE))
    assert torch.equal(current_pose, (t + offset).expand(BATCH, POSE))
    assert torch.equal(actuation, torch.full((BATCH, ACTION), float(t + 1)))
  assert torch.equal(result.predicted_poses[:, 4], (4 + offset + ACTION * 5).expand(BATCH, POSE))


def test_open_loop_holds_the_error_at_zero_and_still_predicts_poses() -> None:
  inverse, forward_model, windows = (
    _ScriptedInverse(),
    _RecordingForwardModel(),
    _numbered_windows(),
  )
  result = rollout(inverse, windows, forward_model, feed_back_error=False)
  assert torch.equal(result.errors, torch.zeros(BATCH, STEPS, POSE))
  assert result.predicted_poses is not None and len(forward_model.calls) == STEPS
  assert rollout(_ScriptedInverse(), windows, feed_back_error=False).predicted_poses is None


def _random_models() -> tuple[ProgressiveLSTM, ForwardModel, BabblingWindows]:
  torch.manual_seed(0)
  network = ProgressiveLSTM(hidden_size=8)
  network.add_column(2 * POSE + ACTION, ACTION)
  network.add_column(2 * POSE + ACTION, ACTION)
  forward_model = ForwardModel(actuation_size=ACTION, hidden_size=16).freeze()
  windows = BabblingWindows(
    torch.rand(8, STEPS + 2, POSE) * 2 - 1,
    torch.rand(8, STEPS, ACTION) * 2 - 1,
    torch.zeros(8, STEPS, 0),
  )
  return network, forward_model, windows


def test_a_sequence_rolls_out_the_same_alone_or_in_any_batch() -> None:
  network, forward_model, windows = _random_models()
  batch = rollout(network, windows, forward_model)
  permutation = torch.randperm(len(windows))
  permuted = rollout(network, windows.subset(permutation), forward_model)
  torch.testing.assert_close(permuted.actions, batch.actions[permutation], rtol=0, atol=1e-6)
  torch.testing.assert_close(permuted.errors, batch.errors[permutation], rtol=0, atol=1e-6)
  for sequence in range(len(windows)):
    alone = rollout(network, windows.subset(torch.tensor([sequence])), forward_model)
    torch.testing.assert_close(alone.actions[0], batch.actions[sequence], rtol=0, atol=1e-6)
    torch.testing.assert_close(alone.errors[0], batch.errors[sequence], rtol=0, atol=1e-6)


class _LearnedFirstAction(InverseModel):
  """Step 0 outputs a learnable action; later steps a fixed linear map of the error input."""

  def __init__(self) -> None:
    super().__init__()
    self.input_size, self.action_size = 2 * POSE + ACTION, ACTION
    self.first_action = nn.Parameter(torch.full((ACTION,), 0.3))
    self.register_buffer("error_readout", torch.randn(POSE, ACTION))

  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    raise NotImplementedError("this probe only runs step by step")

  def initial_state(self, batch_size: int) -> int:
    return 0

  def step(self, inputs: Tensor, state: int) -> InverseStep:
    if state == 0:
      action = self.first_action.expand(inputs.shape[0], ACTION)
    else:
      action = inputs[:, POSE : 2 * POSE] @ self.error_readout
    return InverseStep(action, inputs.new_zeros(()), state + 1)


@pytest.mark.parametrize("feed_back_error", [True, False])
def test_gradients_reach_earlier_actions_only_through_the_fed_back_error(
  feed_back_error: bool,
) -> None:
  _, forward_model, windows = _random_models()
  probe = _LearnedFirstAction()
  result = rollout(probe, windows, forward_model, feed_back_error)
  result.actions[:, 1:].square().sum().backward()
  first_action_gradient = probe.first_action.grad
  assert first_action_gradient is not None  # step 0 is in the stacked actions either way
  assert bool(first_action_gradient.any()) == feed_back_error
  assert all(parameter.grad is None for parameter in forward_model.parameters())


def test_closed_loop_without_a_forward_model_is_refused() -> None:
  with pytest.raises(ValueError, match="forward model"):
    rollout(_ScriptedInverse(), _numbered_windows())


def test_inverse_model_of_the_wrong_width_is_refused() -> None:
  network = ProgressiveLSTM(hidden_size=8)
  network.add_column(2 * POSE + ACTION + 1, ACTION)
  with pytest.raises(ValueError, match="reads 15 features"):
    rollout(network, _numbered_windows(), _RecordingForwardModel())
