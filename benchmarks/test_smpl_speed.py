"""Speed of SMPL training and control on this machine's CPU.

Run with `pytest benchmarks --benchmark-only`. Training is measured on paper-sized data: 9,800
training windows (70 % of 14,000 babbling samples) and 1,400 validation windows, batch 32,
sequence length 15, closed loop through a 2 x 64 LSTM forward model. The column count is the Exp1S
stage: column 5 also runs the four frozen columns before it.
"""

from collections.abc import Iterator

import pytest
import torch

from smpl.fitting import CPU_THREADS
from smpl.fitting import limited_cpu_threads
from smpl.forward_model import ForwardModel
from smpl.progressive import ProgressiveLSTM
from smpl.training import InverseTrainingConfig
from smpl.training import train_inverse_model
from smpl.windows import SEQUENCE_LENGTH
from smpl.windows import BabblingWindows
from smpl.windows import inverse_input_size

POSE_SIZE = 6
TRAIN_WINDOWS = 9_800
VALIDATION_WINDOWS = 1_400
CPU = torch.device("cpu")


@pytest.fixture(autouse=True)
def _training_thread_count() -> Iterator[None]:
  with limited_cpu_threads(CPU_THREADS, CPU):
    yield


def _exp1s_network(columns: int) -> ProgressiveLSTM:
  torch.manual_seed(0)
  network = ProgressiveLSTM()
  for modules in range(1, columns + 1):
    network.add_column(inverse_input_size(POSE_SIZE, 2 * modules), 2 * modules)
  return network


def _random_windows(count: int, action_size: int, seed: int) -> BabblingWindows:
  generator = torch.Generator().manual_seed(seed)
  return BabblingWindows(
    torch.rand(count, SEQUENCE_LENGTH + 2, POSE_SIZE, generator=generator) * 2 - 1,
    torch.rand(count, SEQUENCE_LENGTH, action_size, generator=generator) * 2 - 1,
    torch.zeros(count, SEQUENCE_LENGTH, 0),
  )


@pytest.mark.parametrize("compile_", [False, True], ids=["eager", "compiled"])
@pytest.mark.parametrize("columns", [1, 5])
def test_closed_loop_training_epoch(benchmark, columns: int, compile_: bool) -> None:
  """Four epochs (training and validation) in one `fit`; the figure to read is
  `extra_info["steady_epoch_s"]`, the mean of epochs 2 to 4 (the first one compiles)."""
  network = _exp1s_network(columns)
  action_size = network.action_size
  forward_model = ForwardModel(action_size).freeze()
  train = _random_windows(TRAIN_WINDOWS, action_size, seed=1)
  validation = _random_windows(VALIDATION_WINDOWS, action_size, seed=2)
  config = InverseTrainingConfig(max_epochs=4, patience=4, compile=compile_)

  result = benchmark.pedantic(
    lambda: train_inverse_model(network, forward_model, train, validation, config, CPU),
    rounds=1,
    iterations=1,
  )
  seconds = [report.seconds for report in result.history]
  benchmark.extra_info["epoch_s"] = seconds
  benchmark.extra_info["steady_epoch_s"] = sum(seconds[1:]) / len(seconds[1:])
  benchmark.extra_info["train_windows_per_second"] = TRAIN_WINDOWS / (
    sum(seconds[1:]) / len(seconds[1:])
  )


@pytest.mark.parametrize("columns", [1, 5])
def test_single_step_inference_latency(benchmark, columns: int) -> None:
  network = _exp1s_network(columns).eval()
  inputs = torch.rand(1, network.input_size) * 2 - 1
  state = network.initial_state(batch_size=1)

  def control_step() -> torch.Tensor:
    with torch.no_grad():
      return network.step(inputs, state).action

  action = benchmark(control_step)
  assert action.shape == (1, network.action_size)
