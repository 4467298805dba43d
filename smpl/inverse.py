"""The interface every inverse model (SMPL and the baselines) offers to training and control."""

from __future__ import annotations

from abc import ABC
from abc import abstractmethod
from typing import Any
from typing import NamedTuple

from torch import Tensor
from torch import nn


class InverseStep(NamedTuple):
  """One control step of an inverse model."""

  action: Tensor
  """(batch, action_size) the action a_t."""
  aux_loss: Tensor
  """Scalar regulariser for this step, already weighted (zero for deterministic models)."""
  state: Any
  """The model's recurrent state after this step, to pass to the next `step` call."""


class InverseModel(nn.Module, ABC):
  """Maps inputs [target pose x_{t+1}, pose error e_t, previous action a_{t-1}] to actions a_t.

  Subclasses expose `input_size` and `action_size`. `forward` runs whole sequences from a fresh
  state; `initial_state` + `step` run one control step at a time and must give the same actions,
  so a model trains in the closed loop and controls a robot through the same code.
  """

  input_size: int
  action_size: int
  compiles_on_cpu: bool = True
  """Whether `torch.compile` can compile this model's training on the CPU (`smpl.fitting.fit`
    trains it eagerly there if not)."""

  @abstractmethod
  def forward(self, inputs: Tensor) -> tuple[Tensor, Tensor]:
    """Actions (batch, steps, action_size) and the mean aux loss for (batch, steps, input)."""

  @abstractmethod
  def initial_state(self, batch_size: int) -> Any:
    """The state before the first step of a sequence."""

  @abstractmethod
  def step(self, inputs: Tensor, state: Any) -> InverseStep:
    """Advances one control step for inputs (batch, input_size)."""
