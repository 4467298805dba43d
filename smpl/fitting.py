"""One training loop for every model: Adam, early stopping on validation loss, best weights kept.

`fit` trains any module on any per-batch loss (`smpl.training` supplies the losses of the forward,
inverse and progressive models), resumably inside `smpl.snapshots.resumable`; `TrainingConfig`
holds the optimisation settings every model shares (the paper's learning rate and epoch budget).

Devices: a training runs on `default_device()` (CUDA where there is one) and hands its models back
on the CPU (`on_device`), where a loaded checkpoint is too and where agents act; on the CPU it uses
`CPU_THREADS` intra-op threads (`limited_cpu_threads`).
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Iterator
from contextlib import contextmanager
import dataclasses
from dataclasses import dataclass
from dataclasses import field
import hashlib
import logging
import math
import time
import warnings

import torch
from torch import Tensor
from torch import nn

from smpl import snapshots
from smpl.windows import BabblingWindows

LEARNING_RATE = 1e-3
"""Adam step size (paper, forward model and SMPL)."""
MAX_EPOCHS = 800
"""Epoch budget (paper, forward model and SMPL)."""
PATIENCE = 50
"""Epochs without a lower validation loss before training stops (our choice; the paper ran 800)."""
CPU_THREADS = 1
"""Intra-op threads while training on CPU. The matrices here are small (batch 32 x 64 units), so a
second thread mostly adds synchronisation: on the 2-core development machine 2 threads were no
faster than 1, and with another process on the second core a 32x64 @ 64x256 matmul went from
13 us to 4 ms."""
_VALIDATION_CHUNK = 4096
"""Windows per gradient-free validation pass, to bound memory on large validation sets."""
BatchLoss = Callable[[BabblingWindows], Tensor]


@dataclass(frozen=True)
class TrainingConfig:
  """Optimisation settings every model shares."""

  batch_size: int
  learning_rate: float = LEARNING_RATE
  weight_decay: float = 0.0
  """Adam's L2 penalty on the trainable weights (0: none, as in the paper)."""
  max_epochs: int = MAX_EPOCHS
  patience: int = PATIENCE
  seed: int = 0
  """Seeds batch shuffling and any sampling inside the model (the VAE's latent noise)."""
  cpu_threads: int = CPU_THREADS
  compile: bool = False
  """Compile the training loss and the optimiser step with `torch.compile` (Inductor): on the
    2-core machine an SMPL column's closed-loop epoch over 9,695 windows fell from 2.9 s to 1.2 s,
    after about 40 s of compilation (a few seconds once Inductor's on-disk cache holds it). Falls
    back to eager, with a warning, where compilation fails. Validation stays eager."""


@dataclass(frozen=True)
class EpochReport:
  epoch: int
  train_loss: float
  validation_loss: float
  best_validation_loss: float
  improved: bool
  seconds: float
  resumed: bool = False
  """Run before the training was stopped and resumed: `fit` hands it on again when it resumes
  (a progress bar starts there; its pace is that of the epochs run since)."""


@dataclass
class TrainingResult:
  best_epoch: int
  best_validation_loss: float
  stopped_early: bool
  history: list[EpochReport] = field(default_factory=list)
  restarts: int = 0
  """Times the training started again after diverging (`restart_diverged`)."""
  learning_rate: float | None = None
  """The learning rate of the training kept, when restarts changed it."""

  @property
  def epochs_run(self) -> int:
    return len(self.history)


class EarlyStopping:
  """Tracks the best validation loss; says when `patience` epochs passed without a better one."""

  def __init__(self, patience: int) -> None:
    self.patience = patience
    self.best_loss = math.inf
    self.best_epoch = -1
    self.epochs_without_improvement = 0

  def update(self, epoch: int, loss: float) -> bool:
    """Records one epoch's validation loss; returns whether it is the best so far."""
    if loss < self.best_loss:
      self.best_loss = loss
      self.best_epoch = epoch
      self.epochs_without_improvement = 0
      return True
    self.epochs_without_improvement += 1
    return False

  @property
  def should_stop(self) -> bool:
    return self.epochs_without_improvement >= self.patience


def default_device() -> torch.device:
  """The accelerator (CUDA where there is one) if available, otherwise the CPU."""
  accelerator = torch.accelerator.current_accelerator(check_available=True)
  return accelerator if accelerator is not None else torch.device("cpu")


@contextmanager
def seeded(seed: int, device: torch.device) -> Iterator[None]:
  """Seeds torch's global generators (CPU and `device`) for the block, then restores them."""
  accelerators = [] if device.type == "cpu" else [device]
  with torch.random.fork_rng(devices=accelerators, device_type=device.type):
    torch.manual_seed(seed)
    yield


@contextmanager
def on_device(device: torch.device, *models: nn.Module) -> Iterator[None]:
  """Moves `models` to `device` for the block, then back to the CPU, also when the block raises.

  Between trainings every model lives on the CPU: a checkpoint loads there, and agents act there
  (one step of one sample at a time, which a GPU only slows down), so an agent acts the same
  whether it was trained a moment ago or loaded. Parameters keep their identity (`nn.Module.to`
  moves their data), so an optimiser made inside the block still holds them.
  """
  for model in models:
    model.to(device)
  try:
    yield
  finally:
    for model in models:
      model.to("cpu")


@contextmanager
def limited_cpu_threads(count: int, device: torch.device) -> Iterator[None]:
  """Sets torch's intra-op thread count for the block when computing on the CPU, then restores it.

  See CPU_THREADS; wrap evaluation and control loops in it as well as training.
  """
  if device.type != "cpu":
    yield
    return
  previous = torch.get_num_threads()
  torch.set_num_threads(count)
  try:
    yield
  finally:
    torch.set_num_threads(previous)


def fit(
  model: nn.Module,
  batch_loss: BatchLoss,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: TrainingConfig,
  device: torch.device | None = None,
  on_epoch_end: Callable[[EpochReport], None] | None = None,
  validation_loss: BatchLoss | None = None,
) -> TrainingResult:
  """Trains the trainable parameters of `model` to minimise `batch_loss` on `train`.

  Each epoch shuffles the training windows, takes one Adam step per batch, then scores the whole
  validation set with `validation_loss` (default: `batch_loss`). Training stops after
  `config.max_epochs` or when the validation loss has not improved for `config.patience` epochs;
  the model ends with the weights of its best epoch, in eval mode. The same config and data give
  the same weights. `batch_loss` must use tensors on the model's device: `fit` moves `model` and
  the windows there, nothing else, and hands `model` back on the CPU (`on_device`). Inside
  `smpl.snapshots.resumable`, a stopped fit resumes where it was (`on_epoch_end` then first gets
  the epochs already run, marked `resumed`). A model whose `compiles_on_cpu` is False trains
  eagerly on the CPU whatever `config.compile` says.
  """
  device = device if device is not None else default_device()
  parameters = [parameter for parameter in model.parameters() if parameter.requires_grad]
  if not parameters:
    raise ValueError("the model has no trainable parameters")
  train = train.to(device)
  validation = validation.to(device)
  snapshot = snapshots.next_path()
  fingerprint = _fingerprint(model, train, validation, config) if snapshot else ""
  with (
    on_device(device, model),
    seeded(config.seed, device),
    limited_cpu_threads(config.cpu_threads, device),
  ):
    optimizer = torch.optim.Adam(
      parameters, lr=config.learning_rate, weight_decay=config.weight_decay
    )
    train_loss_of, step = batch_loss, optimizer.step
    if config.compile and (device.type != "cpu" or getattr(model, "compiles_on_cpu", True)):
      train_loss_of, step = _compiled(batch_loss), _compiled(optimizer.step)
    run = _FitState(
      model,
      optimizer,
      torch.Generator().manual_seed(config.seed),
      EarlyStopping(config.patience),
      device,
    )
    saved = snapshots.load(snapshot, fingerprint) if snapshot else None
    if saved is not None:
      run.restore(saved)
      for report in run.history if on_epoch_end is not None else ():
        on_epoch_end(dataclasses.replace(report, resumed=True))
    finished_before = run.finished
    last_saved = time.monotonic()
    while not run.finished and len(run.history) < config.max_epochs:
      started = time.perf_counter()
      model.train()
      train_loss = _train_epoch(
        train_loss_of, step, optimizer, train, config.batch_size, run.shuffling
      )
      epoch_validation_loss = evaluate_loss(model, validation_loss or batch_loss, validation)
      report = run.record(train_loss, epoch_validation_loss, time.perf_counter() - started)
      if snapshot and time.monotonic() - last_saved >= snapshots.SAVE_INTERVAL_S:
        snapshots.save(snapshot, fingerprint, run.state())
        last_saved = time.monotonic()
      if on_epoch_end is not None:
        on_epoch_end(report)
    run.finished = True
    if snapshot and not finished_before:
      snapshots.save(snapshot, fingerprint, run.state())
    model.load_state_dict(run.best_state)
    model.eval()
  stopping = run.stopping
  return TrainingResult(stopping.best_epoch, stopping.best_loss, stopping.should_stop, run.history)


class _FitState:
  """Everything a `fit` carries from one epoch to the next, which a snapshot saves."""

  def __init__(
    self,
    model: nn.Module,
    optimizer: torch.optim.Optimizer,
    shuffling: torch.Generator,
    stopping: EarlyStopping,
    device: torch.device,
  ) -> None:
    self.model = model
    self.optimizer = optimizer
    self.shuffling = shuffling
    self.stopping = stopping
    self.device = device
    self.best_state = copy_state(model)
    self.history: list[EpochReport] = []
    self.finished = False

  def record(self, train_loss: float, validation_loss: float, seconds: float) -> EpochReport:
    """Scores the epoch just trained; keeps the weights if they are the best so far."""
    epoch = len(self.history)
    improved = self.stopping.update(epoch, validation_loss)
    if improved:
      self.best_state = copy_state(self.model)
    report = EpochReport(
      epoch, train_loss, validation_loss, self.stopping.best_loss, improved, seconds
    )
    self.history.append(report)
    self.finished = self.stopping.should_stop
    return report

  def state(self) -> dict:
    """The state to save: weights, optimiser, best weights, early stopping, history, and the
    generators that shuffle batches and draw the model's noise."""
    return {
      "model": copy_state(self.model),
      "optimizer": self.optimizer.state_dict(),
      "best": self.best_state,
      "stopping": [
        self.stopping.best_loss,
        self.stopping.best_epoch,
        self.stopping.epochs_without_improvement,
      ],
      "history": [dataclasses.asdict(report) for report in self.history],
      "shuffling": self.shuffling.get_state(),
      "rng": torch.get_rng_state(),
      "accelerator_rng": (
        torch.cuda.get_rng_state(self.device) if self.device.type == "cuda" else torch.zeros(0)
      ),
      "finished": self.finished,
    }

  def restore(self, state: dict) -> None:
    self.model.load_state_dict(state["model"])
    self.optimizer.load_state_dict(state["optimizer"])
    self.best_state = {name: tensor.to(self.device) for name, tensor in state["best"].items()}
    (
      self.stopping.best_loss,
      self.stopping.best_epoch,
      self.stopping.epochs_without_improvement,
    ) = state["stopping"]
    self.history = [EpochReport(**report) for report in state["history"]]
    self.shuffling.set_state(state["shuffling"])
    torch.set_rng_state(state["rng"])
    if self.device.type == "cuda":
      torch.cuda.set_rng_state(state["accelerator_rng"], self.device)
    self.finished = state["finished"]


def _fingerprint(
  model: nn.Module, train: BabblingWindows, validation: BabblingWindows, config: TrainingConfig
) -> str:
  """What a snapshot must match to be resumed: the config, the data and the initial weights."""
  digest = hashlib.sha256(repr(config).encode())
  for windows in (train, validation):
    for tensor in windows.tensors():
      digest.update(tensor.detach().cpu().contiguous().numpy().tobytes())
  for name, tensor in model.state_dict().items():
    digest.update(name.encode())
    digest.update(tensor.detach().cpu().contiguous().numpy().tobytes())
  return digest.hexdigest()


def evaluate_loss(model: nn.Module, batch_loss: BatchLoss, windows: BabblingWindows) -> float:
  """Mean of `batch_loss` over all windows, in eval mode and without gradients."""
  model.eval()
  chunks = torch.arange(len(windows), device=windows.actions.device).split(_VALIDATION_CHUNK)
  total = 0.0
  with torch.no_grad():
    for indices in chunks:
      total += batch_loss(windows.subset(indices)).item() * len(indices)
  return total / len(windows)


def _train_epoch(
  batch_loss: BatchLoss,
  step: Callable[[], object],
  optimizer: torch.optim.Optimizer,
  train: BabblingWindows,
  batch_size: int,
  shuffling: torch.Generator,
) -> float:
  """One pass over the shuffled training windows; returns the mean training loss."""
  order = torch.randperm(len(train), generator=shuffling).to(train.actions.device)
  total = torch.zeros((), device=train.actions.device)
  for indices in order.split(batch_size):
    loss = batch_loss(train.subset(indices))
    optimizer.zero_grad(set_to_none=True)
    loss.backward()
    step()
    total += loss.detach() * len(indices)
  return total.item() / len(train)


def _is_not_profiler_notice(record: logging.LogRecord) -> bool:
  """False for Dynamo's notice that it skips the optimisers' `record_function` profiler
  markers (harmless, and printed once by every worker process that compiles a step)."""
  return not record.getMessage().startswith("Profiler record function")


def _compiled(function: Callable) -> Callable:
  """`torch.compile(function)`, or `function` itself (with a warning) if compiling fails."""
  notices = logging.getLogger("torch._dynamo.variables.ctx_manager")
  if _is_not_profiler_notice not in notices.filters:
    notices.addFilter(_is_not_profiler_notice)
  # The LSTM layers run through torch.lstm_cell with nn.LSTM's weights; Dynamo refuses to touch
  # nn.LSTM modules unless told that this is fine.
  torch._dynamo.config.allow_rnn = True
  compiled = torch.compile(function)
  fell_back = False

  def run(*args, **kwargs):
    nonlocal fell_back
    if not fell_back:
      try:
        return compiled(*args, **kwargs)
      except Exception as error:  # Inductor needs a C++ compiler, among other things.
        fell_back = True
        warnings.warn(
          f"torch.compile failed ({type(error).__name__}); training in eager mode",
          RuntimeWarning,
          stacklevel=2,
        )
    return function(*args, **kwargs)

  return run


def copy_state(model: nn.Module) -> dict[str, Tensor]:
  return {name: tensor.detach().clone() for name, tensor in model.state_dict().items()}
