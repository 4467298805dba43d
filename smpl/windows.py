"""The data contract of the learners: fixed-length windows cut from a motor-babbling recording.

Time convention (all arrays in normalised units, [-1, 1]). In a recording, action a_s is applied
while the arm is at pose x_s and brings it to pose x_{s+1}. A window covers T consecutive control
steps; inside it, local step t = 0 .. T-1 applies a_t at x_t and reaches x_{t+1}. Besides those
poses a window holds x_{-1}, the pose before its first step, because the forward model reads the
previous and the current pose:

    poses[:, 0]     = x_{-1}
    poses[:, t + 1] = x_t        (t = -1 .. T)
    actions[:, t]   = a_t        (t = 0 .. T-1)

so that `previous_poses[:, t] = x_{t-1}`, `current_poses[:, t] = x_t` and
`next_poses[:, t] = x_{t+1}` (the target the inverse model is given at step t).
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor

SEQUENCE_LENGTH = 15
"""Control steps per window for every recurrent model (paper, forward model and SMPL training)."""


def inverse_input_size(pose_size: int, action_size: int) -> int:
  """Width of the inverse-model input [target pose, pose error, previous action]."""
  return 2 * pose_size + action_size


def inverse_inputs(target_pose: Tensor, pose_error: Tensor, previous_action: Tensor) -> Tensor:
  """The inverse-model input at one step: [x_{t+1}, e_t, a_{t-1}] along the last axis."""
  return torch.cat([target_pose, pose_error, previous_action], dim=-1)


@dataclass(frozen=True)
class BabblingWindows:
  """A batch of babbling windows (see the module docstring for the time indexing).

  Attributes:
      poses: (N, T + 2, pose_size) x_{-1} .. x_T.
      actions: (N, T, action_size) a_0 .. a_{T-1}: the actuation the inverse model learns to
          produce (one module in Exp2S, the whole arm in Exp1S).
      preceding_actions: (N, T, p) actuation of the modules before this one, which the forward
          model also reads (Exp2S/Exp2R coupling); p = 0 when there are none.
  """

  poses: Tensor
  actions: Tensor
  preceding_actions: Tensor

  def __post_init__(self) -> None:
    if self.poses.dim() != 3 or self.actions.dim() != 3 or self.preceding_actions.dim() != 3:
      raise ValueError("poses, actions and preceding_actions must be (windows, steps, features)")
    count, steps = self.actions.shape[:2]
    if self.poses.shape[:2] != (count, steps + 2):
      raise ValueError(
        f"poses must be (N, T + 2, pose) = ({count}, {steps + 2}, ...) for actions "
        f"{tuple(self.actions.shape)}, got {tuple(self.poses.shape)}"
      )
    if self.preceding_actions.shape[:2] != (count, steps):
      raise ValueError(
        f"preceding_actions must be ({count}, {steps}, p), "
        f"got {tuple(self.preceding_actions.shape)}"
      )

  @classmethod
  def from_recording(
    cls,
    poses: Tensor,
    actions: Tensor,
    preceding_actions: Tensor | None = None,
    window_length: int = SEQUENCE_LENGTH,
    stride: int = 1,
  ) -> BabblingWindows:
    """Cuts every window that fits in one contiguous recording.

    Args:
        poses: (S, pose_size) x_0 .. x_{S-1}.
        actions: (S, action_size); actions[s] is applied at poses[s] and reaches poses[s + 1]
            (the last one has no recorded outcome and is unused).
        preceding_actions: (S, p) actuation of preceding modules, or None for p = 0.
        window_length: control steps T per window.
        stride: recording steps between the starts of consecutive windows.

    Windows never leave the recording, so cut each data split from its own recording.
    """
    if preceding_actions is None:
      preceding_actions = actions.new_zeros(actions.shape[0], 0)
    if not poses.shape[0] == actions.shape[0] == preceding_actions.shape[0]:
      raise ValueError("poses, actions and preceding_actions must have one row per time step")
    # A window whose first control step is s needs poses s-1 .. s+T and actions s .. s+T-1.
    first_steps = torch.arange(1, poses.shape[0] - window_length, stride)
    if first_steps.numel() == 0:
      raise ValueError(
        f"a recording of {poses.shape[0]} steps is too short for windows of {window_length}"
      )
    pose_index = first_steps[:, None] - 1 + torch.arange(window_length + 2)
    action_index = first_steps[:, None] + torch.arange(window_length)
    return cls(poses[pose_index], actions[action_index], preceding_actions[action_index])

  def __len__(self) -> int:
    return self.actions.shape[0]

  @property
  def steps(self) -> int:
    return self.actions.shape[1]

  @property
  def pose_size(self) -> int:
    return self.poses.shape[2]

  @property
  def action_size(self) -> int:
    return self.actions.shape[2]

  @property
  def actuation_size(self) -> int:
    """Width of the forward model's actuation input: preceding modules' and this one's."""
    return self.preceding_actions.shape[2] + self.action_size

  @property
  def previous_poses(self) -> Tensor:
    """(N, T, pose_size): x_{t-1} for each step t."""
    return self.poses[:, :-2]

  @property
  def current_poses(self) -> Tensor:
    """(N, T, pose_size): x_t for each step t."""
    return self.poses[:, 1:-1]

  @property
  def next_poses(self) -> Tensor:
    """(N, T, pose_size): x_{t+1} for each step t, the inverse model's targets."""
    return self.poses[:, 2:]

  def actuation(self, actions: Tensor, step: int | None = None) -> Tensor:
    """The forward model's actuation input: preceding modules' actuation followed by `actions`.

    `actions` is (N, T, action_size) for the whole window, or (N, action_size) together with
    the `step` it belongs to.
    """
    if self.preceding_actions.shape[-1] == 0:
      return actions
    preceding = self.preceding_actions if step is None else self.preceding_actions[:, step]
    return torch.cat([preceding, actions], dim=-1)

  def subset(self, indices: Tensor) -> BabblingWindows:
    return BabblingWindows(
      self.poses[indices], self.actions[indices], self.preceding_actions[indices]
    )

  def to(self, device: torch.device) -> BabblingWindows:
    return BabblingWindows(
      self.poses.to(device), self.actions.to(device), self.preceding_actions.to(device)
    )

  def tensors(self) -> tuple[Tensor, ...]:
    """Every tensor of the windows (to fingerprint the data)."""
    return self.poses, self.actions, self.preceding_actions


@dataclass(frozen=True)
class ModuleWindows:
  """Time-aligned windows of every module of one arm (window i of each module covers the same
  control steps), for training a distributed controller's columns together.

  It offers what `smpl.fitting.fit` uses of BabblingWindows: `len`, `subset`, `to`, `actions`,
  `tensors`.
  """

  modules: tuple[BabblingWindows, ...]

  def __post_init__(self) -> None:
    counts = {(len(windows), windows.steps) for windows in self.modules}
    if len(counts) != 1:
      raise ValueError(f"module windows are not aligned: (windows, steps) {sorted(counts)}")

  def __len__(self) -> int:
    return len(self.modules[0])

  @property
  def actions(self) -> Tensor:
    """The first module's actions (for the device and the count)."""
    return self.modules[0].actions

  def subset(self, indices: Tensor) -> ModuleWindows:
    return ModuleWindows(tuple(windows.subset(indices) for windows in self.modules))

  def to(self, device: torch.device) -> ModuleWindows:
    return ModuleWindows(tuple(windows.to(device) for windows in self.modules))

  def tensors(self) -> tuple[Tensor, ...]:
    return tuple(tensor for windows in self.modules for tensor in windows.tensors())
