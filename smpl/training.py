"""One training loop for every model: Adam, early stopping on validation loss, best weights kept.

`fit` trains any module on any per-batch loss. `train_forward_model` and `train_inverse_model` are
thin wrappers that supply the loss: teacher-forced next-pose MSE for the forward model, and for
inverse models the action MSE of a closed-loop (or open-loop) rollout through the frozen forward
model (see `smpl.rollout` for the exact time indexing).

Inverse-model loss: MSE between predicted and babbling actions (supervised, as in the paper), plus
the model's aux loss (the VAE's beta * KL), plus optionally `pose_loss_weight` times the MSE between
the forward model's predicted poses and the targets (off by default). The aux loss is a training
regulariser only: validation, and so early stopping and the best weights kept, leaves it out, which
makes every inverse model's validation loss the same quantity.

Divergence: given `restart_diverged`, an inverse-model training has diverged when its best
validation loss is no lower than that of always acting zero (the middle of the normalised action
range) and an epoch's training loss rose to `DIVERGED_LOSS_FACTOR` times that (a short training
that has not learned yet is not diverged); it starts again from its initial weights with half
the learning rate, at most `DIVERGENCE_RESTARTS` times, with a warning each time. A training that
did not diverge is untouched, to the bit.

Devices: a training runs on `default_device()` (CUDA where there is one) and hands its models back
on the CPU (`on_device`), where a loaded checkpoint is too and where agents act.
"""

from __future__ import annotations

from collections.abc import Callable
from collections.abc import Iterator
from collections.abc import Sequence
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
from smpl.forward_model import ForwardModel
from smpl.inverse import InverseModel
from smpl.progressive import ProgressiveLSTM
from smpl.rollout import joint_rollout
from smpl.rollout import rollout
from smpl.windows import BabblingWindows
from smpl.windows import ModuleWindows

LEARNING_RATE = 1e-3
"""Adam step size (paper, forward model and SMPL)."""
MAX_EPOCHS = 800
"""Epoch budget (paper, forward model and SMPL)."""
FORWARD_BATCH_SIZE = 64
"""Windows per forward-model batch (paper)."""
INVERSE_BATCH_SIZE = 32
"""Windows per inverse-model batch (paper, SMPL)."""
PATIENCE = 50
"""Epochs without a lower validation loss before training stops (our choice; the paper ran 800)."""
CPU_THREADS = 1
"""Intra-op threads while training on CPU. The matrices here are small (batch 32 x 64 units), so a
second thread mostly adds synchronisation: on the 2-core development machine 2 threads were no
faster than 1, and with another process on the second core a 32x64 @ 64x256 matmul went from
13 us to 4 ms."""
DIVERGENCE_RESTARTS = 3
"""Restarts of a diverged inverse-model training, each with half the previous learning rate. The
MLP's tuned rate (8.3e-3) diverged on 3 of 5 seeds of pneumatic-433's 14,000 samples (gradient
norms up to 2.5e5 in the first epoch). The rule sees only the weights kept: a training that
diverges after a good enough epoch keeps that epoch."""
DIVERGED_LOSS_FACTOR = 10.0
"""How far above acting zero's loss an epoch's training loss must rise for a training that ends no
better than acting zero to count as diverged. The MLP's diverged trainings reached 35 to 175
times; undertrained ones (2 epochs of the tests' tiny profile) stay near 1."""
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
class ForwardTrainingConfig(TrainingConfig):
  batch_size: int = FORWARD_BATCH_SIZE


@dataclass(frozen=True)
class InverseTrainingConfig(TrainingConfig):
  batch_size: int = INVERSE_BATCH_SIZE
  feed_back_error: bool = True
  """Closed loop (the error input comes from the forward model) or open loop (it stays zero)."""
  pose_loss_weight: float = 0.0
  """Weight of the forward-model pose MSE added to the action MSE; 0 trains on actions only."""


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
    self.best_state = _copy_state(model)
    self.history: list[EpochReport] = []
    self.finished = False

  def record(self, train_loss: float, validation_loss: float, seconds: float) -> EpochReport:
    """Scores the epoch just trained; keeps the weights if they are the best so far."""
    epoch = len(self.history)
    improved = self.stopping.update(epoch, validation_loss)
    if improved:
      self.best_state = _copy_state(self.model)
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
      "model": _copy_state(self.model),
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


def forward_model_loss(forward_model: ForwardModel, windows: BabblingWindows) -> Tensor:
  """Next-pose MSE with the recorded poses and actuation as inputs (teacher forcing)."""
  predicted = forward_model(
    windows.previous_poses, windows.current_poses, windows.actuation(windows.actions)
  )
  return nn.functional.mse_loss(predicted, windows.next_poses)


def inverse_model_loss(
  inverse_model: InverseModel,
  forward_model: ForwardModel,
  windows: BabblingWindows,
  feed_back_error: bool = True,
  pose_loss_weight: float = 0.0,
  include_aux_loss: bool = True,
) -> Tensor:
  """Action MSE of a rollout, plus aux loss (unless `include_aux_loss` is false), plus the
  optional pose term (module docstring)."""
  needs_forward_model = feed_back_error or pose_loss_weight > 0
  result = rollout(
    inverse_model, windows, forward_model if needs_forward_model else None, feed_back_error
  )
  loss = nn.functional.mse_loss(result.actions, windows.actions)
  if include_aux_loss:
    loss = loss + result.aux_loss
  if pose_loss_weight > 0:
    loss = loss + pose_loss_weight * nn.functional.mse_loss(
      result.predicted_poses, windows.next_poses
    )
  return loss


def train_forward_model(
  forward_model: ForwardModel,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: TrainingConfig = ForwardTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[EpochReport], None] | None = None,
) -> TrainingResult:
  """Trains the forward model on babbling windows, then freezes it."""
  result = fit(
    forward_model,
    lambda windows: forward_model_loss(forward_model, windows),
    train,
    validation,
    config,
    device,
    on_epoch_end,
  )
  forward_model.freeze()
  return result


def train_inverse_model(
  inverse_model: InverseModel,
  forward_model: ForwardModel,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[EpochReport], None] | None = None,
  restart_diverged: bool = False,
) -> TrainingResult:
  """Trains an inverse model (any of them, including the last SMPL column) through the loop;
  validation leaves out the model's aux loss; `restart_diverged`: see the module docstring."""
  if not forward_model.is_frozen:
    raise ValueError("the forward model must be trained and frozen before the inverse model")
  device = device if device is not None else default_device()
  forward_model.eval()

  def loss(windows: BabblingWindows, include_aux_loss: bool = True) -> Tensor:
    return inverse_model_loss(
      inverse_model,
      forward_model,
      windows,
      config.feed_back_error,
      config.pose_loss_weight,
      include_aux_loss,
    )

  with on_device(device, forward_model):
    return _fit_restarting(
      inverse_model,
      loss,
      train,
      validation,
      config,
      device,
      on_epoch_end,
      lambda windows: loss(windows, include_aux_loss=False),
      _zero_action_loss([validation.actions]) if restart_diverged else None,
    )


def train_column_jointly(
  network: ProgressiveLSTM,
  forward_models: Sequence[ForwardModel],
  train: ModuleWindows,
  validation: ModuleWindows,
  config: InverseTrainingConfig = InverseTrainingConfig(),
  device: torch.device | None = None,
  on_epoch_end: Callable[[EpochReport], None] | None = None,
  column: int | None = None,
  restart_diverged: bool = False,
) -> TrainingResult:
  """Trains one of columns 0..M-1 (M = modules in `train`) of a distributed controller, all
  columns acting together on their own modules (`smpl.rollout.joint_rollout`).

  By default the column is the last, M-1, and the loss is the action MSE of its module; every
  earlier column must be trained and frozen. Given an earlier `column` (retraining it, e.g.
  after an actuator fault), the loss is the mean action MSE of modules `column`..M-1, every
  module whose column reads it through the lateral connections, and every other column must
  be frozen. `restart_diverged`: see the module docstring.
  """
  last = len(train.modules) - 1
  if column is not None and not 0 <= column <= last:
    raise ValueError(f"column must be 0 to {last} for {last + 1} modules, got {column}")
  column = last if column is None else column
  others = [network.columns[index] for index in range(len(network.columns)) if index != column]
  if any(parameter.requires_grad for other in others for parameter in other.parameters()):
    raise ValueError(
      "the earlier columns must be frozen before the next one trains"
      if column == last
      else f"every column but {column} must be frozen to retrain it"
    )
  if not all(model.is_frozen for model in forward_models):
    raise ValueError("the forward models must be trained and frozen before the inverse model")
  device = device if device is not None else default_device()
  for model in forward_models:
    model.eval()

  loss = joint_action_loss(network, forward_models, column, config.feed_back_error)
  zero_action_loss = (
    _zero_action_loss([w.actions for w in validation.modules[column:]])
    if restart_diverged
    else None
  )
  with on_device(device, *forward_models):
    return _fit_restarting(
      network, loss, train, validation, config, device, on_epoch_end, None, zero_action_loss
    )


def joint_action_loss(
  network: ProgressiveLSTM,
  forward_models: Sequence[ForwardModel],
  first: int = 0,
  feed_back_error: bool = True,
  acted_preceding: bool = False,
) -> BatchLoss:
  """The batch loss of columns acting together (`smpl.rollout.joint_rollout`): the mean over
  modules `first`..M-1 of each module's action MSE."""

  def loss(windows: ModuleWindows) -> Tensor:
    results = joint_rollout(network, windows, forward_models, feed_back_error, acted_preceding)
    losses = [
      nn.functional.mse_loss(results[index].actions, windows.modules[index].actions)
      for index in range(first, len(windows.modules))
    ]
    return sum(losses[1:], losses[0]) / len(losses)

  return loss


def _zero_action_loss(actions: Sequence[Tensor]) -> float:
  """The validation loss of always acting zero: the mean over modules of each one's mean
  squared normalised action."""
  return sum(float(torch.mean(module**2)) for module in actions) / len(actions)


def _diverged(result: TrainingResult, zero_action_loss: float) -> bool:
  """Whether a training diverged (module docstring)."""
  return (
    result.best_validation_loss >= zero_action_loss
    and max(report.train_loss for report in result.history)
    >= DIVERGED_LOSS_FACTOR * zero_action_loss
  )


def _fit_restarting(
  model: nn.Module,
  batch_loss: BatchLoss,
  train: BabblingWindows,
  validation: BabblingWindows,
  config: TrainingConfig,
  device: torch.device | None,
  on_epoch_end: Callable[[EpochReport], None] | None,
  validation_loss: BatchLoss | None,
  zero_action_loss: float | None,
) -> TrainingResult:
  """`fit`; when `zero_action_loss` is given, a diverged fit (`_diverged`) starts again from
  the initial weights with half the learning rate (module docstring)."""
  initial = _copy_state(model) if zero_action_loss is not None else None
  for restart in range(DIVERGENCE_RESTARTS + 1):
    result = fit(
      model, batch_loss, train, validation, config, device, on_epoch_end, validation_loss
    )
    if zero_action_loss is None or not _diverged(result, zero_action_loss):
      break
    if restart == DIVERGENCE_RESTARTS:
      warnings.warn(
        f"training of seed {config.seed} still diverged after {restart} "
        f"restarts (best validation loss {result.best_validation_loss:.3g}, "
        f"acting zero {zero_action_loss:.3g}, learning rate "
        f"{config.learning_rate:.3g})"
      )
      break
    warnings.warn(
      f"training of seed {config.seed} diverged (best validation loss "
      f"{result.best_validation_loss:.3g}, no lower than {zero_action_loss:.3g} "
      f"for acting zero); training again from the initial weights with "
      f"learning rate {config.learning_rate / 2:.3g}"
    )
    model.load_state_dict(initial)
    config = dataclasses.replace(config, learning_rate=config.learning_rate / 2)
  if restart:
    result.restarts, result.learning_rate = restart, config.learning_rate
  return result


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


def _copy_state(model: nn.Module) -> dict[str, Tensor]:
  return {name: tensor.detach().clone() for name, tensor in model.state_dict().items()}
