"""Running an inverse model through babbling windows, in closed loop with a frozen forward model.

Indexing (window-local control steps t = 0 .. T-1; see `smpl.windows` for the data layout):

    u_t      = [x_{t+1}, e_t, a'_{t-1}]                inverse-model input
    a'_t     = inverse(u_t | inverse state)             predicted action
    x'_{t+1} = forward(x_{t-1}, x_t, [p_t, a'_t] | forward state)
    e_{t+1}  = x_{t+1} - x'_{t+1}

with e_0 = 0 and a'_{-1} = 0. In words: the target at step t is x_{t+1}; the forward model says
where the predicted action a'_t takes the arm, x'_{t+1}; the signed miss x_{t+1} - x'_{t+1} is the
error the inverse model reads at the next step, together with a'_t as its previous action. So the
error at step t depends only on the predicted actions of steps 0 .. t-1 of the same window, and in
physics it is the same quantity: the previous step's target minus the measured pose.

The forward model reads the recorded poses x_{t-1}, x_t (one-step prediction, as it was trained),
the preceding modules' recorded actuation p_t and the predicted action. Both models carry their
recurrent state through the window. Gradients flow through the frozen forward model: the loss on
a'_t reaches a'_0 .. a'_{t-1} through the errors. In open loop the error input stays zero; the
forward model, if given, still predicts poses for scoring.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import torch
from torch import Tensor

from smpl.forward_model import ForwardModel
from smpl.inverse import InverseModel
from smpl.progressive import ProgressiveLSTM
from smpl.windows import BabblingWindows
from smpl.windows import ModuleWindows
from smpl.windows import inverse_input_size
from smpl.windows import inverse_inputs


@dataclass(frozen=True)
class Rollout:
  """What an inverse model did over a batch of windows."""

  actions: Tensor
  """(N, T, action_size) predicted actions a'_t."""
  errors: Tensor
  """(N, T, pose_size) the error input e_t each step read (zero at t = 0, and in open loop)."""
  predicted_poses: Tensor | None
  """(N, T, pose_size) x'_{t+1} from the forward model, or None without one."""
  aux_loss: Tensor
  """Mean over steps of the model's weighted regulariser (zero for deterministic models)."""


def rollout(
  inverse_model: InverseModel,
  windows: BabblingWindows,
  forward_model: ForwardModel | None = None,
  feed_back_error: bool = True,
) -> Rollout:
  """Runs `inverse_model` step by step through every window; see the module docstring."""
  if feed_back_error and forward_model is None:
    raise ValueError("closed-loop rollout needs a forward model to compute the pose error")
  expected_input = inverse_input_size(windows.pose_size, windows.action_size)
  if inverse_model.input_size != expected_input:
    raise ValueError(
      f"the inverse model reads {inverse_model.input_size} features but windows with "
      f"{windows.pose_size}-D poses and {windows.action_size}-D actions give {expected_input}"
    )
  batch_size = len(windows)
  inverse_state = inverse_model.initial_state(batch_size)
  forward_state = None if forward_model is None else forward_model.initial_state(batch_size)
  error = windows.poses.new_zeros(batch_size, windows.pose_size)
  previous_action = windows.actions.new_zeros(batch_size, windows.action_size)
  previous_poses = windows.previous_poses.unbind(1)
  current_poses = windows.current_poses.unbind(1)
  targets = windows.next_poses.unbind(1)
  actions, errors, predicted_poses, aux_losses = [], [], [], []
  for t, target in enumerate(targets):
    step = inverse_model.step(inverse_inputs(target, error, previous_action), inverse_state)
    inverse_state = step.state
    errors.append(error)
    actions.append(step.action)
    aux_losses.append(step.aux_loss)
    if forward_model is not None:
      predicted_pose, forward_state = forward_model.step(
        previous_poses[t],
        current_poses[t],
        windows.actuation(step.action, t),
        forward_state,
      )
      predicted_poses.append(predicted_pose)
      if feed_back_error:
        error = target - predicted_pose
    previous_action = step.action
  return Rollout(
    actions=torch.stack(actions, dim=1),
    errors=torch.stack(errors, dim=1),
    predicted_poses=torch.stack(predicted_poses, dim=1) if predicted_poses else None,
    aux_loss=torch.stack(aux_losses).mean(),
  )


def joint_rollout(
  network: ProgressiveLSTM,
  windows: ModuleWindows,
  forward_models: Sequence[ForwardModel],
  feed_back_error: bool = True,
  acted_preceding: bool = False,
) -> list[Rollout]:
  """Runs columns 0..len(windows.modules)-1 together, column j on module j's own inputs.

  The same loop as `rollout`, for every module at once: at step t column j reads
  [x^j_{t+1}, e^j_t, a'^j_{t-1}], one `step_columns` call gives every column's action, and
  module j's forward model turns a'^j_t into the next error e^j_{t+1}. Through the lateral
  connections a distal column sees the proximal columns' features of their own targets and
  errors, which its module's pose depends on.

  Module j's forward model reads the preceding modules' recorded actuation (the paper's design),
  or with `acted_preceding` the actions columns 0..j-1 just took, so that a proximal column's
  error reaches the distal modules' errors; module j's preceding actuation must then be modules
  0..j-1's actions in order, normalised alike (`softbench.data.View.module`'s are).
  """
  modules = windows.modules
  if len(forward_models) != len(modules):
    raise ValueError(
      f"{len(modules)} modules need as many forward models, got {len(forward_models)}"
    )
  batch_size = len(windows)
  state = network.initial_state(batch_size, len(modules) - 1)
  forward_states = [model.initial_state(batch_size) for model in forward_models]
  errors = [w.poses.new_zeros(batch_size, w.pose_size) for w in modules]
  previous = [w.actions.new_zeros(batch_size, w.action_size) for w in modules]
  history = [([], [], []) for _ in modules]  # actions, errors, predicted poses
  for t in range(windows.modules[0].steps):
    inputs = [
      inverse_inputs(w.next_poses[:, t], error, action)
      for w, error, action in zip(modules, errors, previous)
    ]
    actions, state = network.step_columns(inputs, state, len(modules) - 1)
    for j, (w, model, action) in enumerate(zip(modules, forward_models, actions)):
      actuation = (
        torch.cat([*actions[:j], action], dim=-1) if acted_preceding else w.actuation(action, t)
      )
      predicted, forward_states[j] = model.step(
        w.previous_poses[:, t], w.current_poses[:, t], actuation, forward_states[j]
      )
      history[j][0].append(action)
      history[j][1].append(errors[j])
      history[j][2].append(predicted)
      if feed_back_error:
        errors[j] = w.next_poses[:, t] - predicted
    previous = actions
  zero = modules[0].actions.new_zeros(())
  return [
    Rollout(torch.stack(a, 1), torch.stack(e, 1), torch.stack(p, 1), zero) for a, e, p in history
  ]
