import pytest
import torch

from smpl.windows import BabblingWindows
from smpl.windows import inverse_input_size
from smpl.windows import inverse_inputs


def _recording(steps: int) -> tuple[torch.Tensor, torch.Tensor]:
  """Poses and actions whose values are their recording step, to read indices back."""
  step_index = torch.arange(steps, dtype=torch.float32)[:, None]
  return step_index.expand(steps, 6).clone(), step_index.expand(steps, 2).clone()


def test_windows_hold_previous_current_and_next_poses_around_each_action() -> None:
  poses, actions = _recording(40)
  windows = BabblingWindows.from_recording(poses, actions, window_length=15)
  assert len(windows) == 40 - 15 - 1
  for window in range(len(windows)):
    first_step = window + 1  # the first window needs the pose before its first step
    steps = torch.arange(first_step, first_step + 15, dtype=torch.float32)
    assert torch.equal(windows.actions[window, :, 0], steps)
    assert torch.equal(windows.previous_poses[window, :, 0], steps - 1)
    assert torch.equal(windows.current_poses[window, :, 0], steps)
    assert torch.equal(windows.next_poses[window, :, 0], steps + 1)


def test_stride_skips_window_starts() -> None:
  poses, actions = _recording(40)
  windows = BabblingWindows.from_recording(poses, actions, window_length=5, stride=3)
  assert windows.actions[:, 0, 0].tolist() == list(range(1, 40 - 5, 3))


def test_actuation_puts_preceding_modules_first() -> None:
  poses, actions = _recording(30)
  preceding = -actions[:, :1]
  windows = BabblingWindows.from_recording(poses, actions, preceding_actions=preceding)
  assert windows.actuation_size == 3
  full = windows.actuation(windows.actions)
  assert torch.equal(full[..., 0], -windows.actions[..., 0])
  assert torch.equal(windows.actuation(windows.actions[:, 4], step=4), full[:, 4])


def test_recording_too_short_for_one_window_is_refused() -> None:
  poses, actions = _recording(16)
  with pytest.raises(ValueError, match="too short"):
    BabblingWindows.from_recording(poses, actions, window_length=15)


def test_inconsistent_shapes_are_refused() -> None:
  with pytest.raises(ValueError, match="T \\+ 2"):
    BabblingWindows(torch.zeros(4, 15, 6), torch.zeros(4, 15, 2), torch.zeros(4, 15, 0))


def test_inverse_input_layout_is_target_error_previous_action() -> None:
  target, error, previous_action = torch.ones(3, 6), 2 * torch.ones(3, 6), 3 * torch.ones(3, 2)
  inputs = inverse_inputs(target, error, previous_action)
  assert inputs.shape[-1] == inverse_input_size(6, 2)
  assert inputs[0].tolist() == [1.0] * 6 + [2.0] * 6 + [3.0] * 2
