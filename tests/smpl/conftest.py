"""A synthetic arm with known smooth dynamics, so learners can be tested without MuJoCo."""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Iterator
import importlib
import inspect
import pkgutil

import pytest
import torch

import smpl
from smpl.fitting import CPU_THREADS
from smpl.fitting import limited_cpu_threads
from smpl.forward_model import ForwardModel
from smpl.inverse import InverseModel
from smpl.training import INVERSE_BATCH_SIZE
from smpl.training import ForwardTrainingConfig
from smpl.training import train_forward_model
from smpl.windows import SEQUENCE_LENGTH
from smpl.windows import BabblingWindows

POSE_SIZE = 6
LAG = 0.5
SHORT_WINDOW = 2  # Control steps per window of the compile tests' data.
"""Fraction of the previous pose the synthetic arm keeps each step (first-order lag)."""


@pytest.fixture(scope="session", autouse=True)
def _few_cpu_threads() -> Iterator[None]:
  """Runs these tiny models on the thread count training uses (see smpl.fitting.CPU_THREADS)."""
  with limited_cpu_threads(CPU_THREADS, torch.device("cpu")):
    yield


def synthetic_windows(
  recording_steps: int,
  action_size: int,
  seed: int,
  arm_seed: int = 0,
  window_length: int = SEQUENCE_LENGTH,
) -> BabblingWindows:
  """Windows of random babbling on an arm with x_{s+1} = LAG x_s + (1 - LAG) tanh(a_s M).

  `arm_seed` picks the arm (the fixed matrix M), `seed` the babbling actions.
  """
  arm = torch.Generator().manual_seed(arm_seed)
  mixing = torch.randn(action_size, POSE_SIZE, generator=arm)
  babbling = torch.Generator().manual_seed(seed)
  actions = torch.rand(recording_steps, action_size, generator=babbling) * 2 - 1
  poses = torch.zeros(recording_steps, POSE_SIZE)
  for step in range(1, recording_steps):
    steady_pose = torch.tanh(actions[step - 1] @ mixing)
    poses[step] = LAG * poses[step - 1] + (1 - LAG) * steady_pose
  return BabblingWindows.from_recording(poses, actions, window_length=window_length)


@pytest.fixture(scope="session")
def make_arm_windows() -> Callable[..., BabblingWindows]:
  """`synthetic_windows`, for tests that build arms of their own."""
  return synthetic_windows


@pytest.fixture(scope="session")
def arm_data() -> dict[str, BabblingWindows]:
  """Training and validation windows of one two-input synthetic arm, from separate recordings."""
  return {
    "train": synthetic_windows(400, action_size=2, seed=1),
    "validation": synthetic_windows(150, action_size=2, seed=2),
  }


@pytest.fixture(scope="session")
def short_arm_data() -> dict[str, BabblingWindows]:
  """`arm_data`'s recordings cut into windows of `SHORT_WINDOW` steps: a closed-loop training
  step unrolls its window, so compiling it takes a fraction of the time of full windows. The
  training windows fill whole batches: a smaller last batch compiles the step a second time, for
  dynamic shapes (about a third of the compiling, measured)."""
  train = synthetic_windows(400, action_size=2, seed=1, window_length=SHORT_WINDOW)
  whole_batches = len(train) // INVERSE_BATCH_SIZE * INVERSE_BATCH_SIZE
  return {
    "train": train.subset(torch.arange(whole_batches)),
    "validation": synthetic_windows(150, action_size=2, seed=2, window_length=SHORT_WINDOW),
  }


@pytest.fixture(scope="session")
def trained_forward_model(arm_data: dict[str, BabblingWindows]) -> ForwardModel:
  """A frozen forward model of the synthetic arm (shared; never modify it in a test)."""
  torch.manual_seed(0)
  forward_model = ForwardModel(actuation_size=2)
  train_forward_model(
    forward_model,
    arm_data["train"],
    arm_data["validation"],
    ForwardTrainingConfig(max_epochs=60, batch_size=32),
    device=torch.device("cpu"),
  )
  return forward_model


@pytest.fixture(scope="session")
def inverse_model_classes() -> set[type]:
  """Every concrete `InverseModel` class of the smpl package (all its modules imported), so
  that a test over "every inverse model" can check that it lists them all."""
  for module in pkgutil.iter_modules(smpl.__path__):
    importlib.import_module(f"smpl.{module.name}")

  def subclasses(cls: type) -> Iterator[type]:
    for subclass in cls.__subclasses__():
      yield subclass
      yield from subclasses(subclass)

  return {
    cls
    for cls in subclasses(InverseModel)
    if not inspect.isabstract(cls) and cls.__module__.startswith("smpl.")
  }
