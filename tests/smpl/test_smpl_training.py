import dataclasses
import io
import logging
import warnings

import pytest
import torch

from smpl import fitting
from smpl import training
from smpl.baselines import BiLSTMInverse
from smpl.baselines import LSTMInverse
from smpl.baselines import MLPInverse
from smpl.baselines import VAELSTMInverse
from smpl.fitting import EarlyStopping
from smpl.fitting import evaluate_loss
from smpl.fitting import fit
from smpl.forward_model import ForwardModel
from smpl.progressive import ProgressiveColumn
from smpl.progressive import ProgressiveLSTM
from smpl.training import ForwardTrainingConfig
from smpl.training import InverseTrainingConfig
from smpl.training import forward_model_loss
from smpl.training import inverse_model_loss
from smpl.training import train_forward_model
from smpl.training import train_inverse_model
from smpl.windows import BabblingWindows
from smpl.windows import inverse_input_size

CPU = torch.device("cpu")
SHORT_RUN = InverseTrainingConfig(max_epochs=3, patience=3)


def _fresh_column(seed: int = 0) -> ProgressiveLSTM:
  torch.manual_seed(seed)
  network = ProgressiveLSTM()
  network.add_column(inverse_input_size(6, 2), 2)
  return network


def _state(model: torch.nn.Module) -> dict[str, torch.Tensor]:
  return {name: value.clone() for name, value in model.state_dict().items()}


@pytest.mark.parametrize("feed_back_error", [True, False])
def test_inverse_model_learns_the_synthetic_arm_in_the_loop(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel, feed_back_error: bool
) -> None:
  network = _fresh_column()
  config = InverseTrainingConfig(max_epochs=12, feed_back_error=feed_back_error)

  def validation_loss() -> float:
    return evaluate_loss(
      network,
      lambda windows: inverse_model_loss(network, trained_forward_model, windows, feed_back_error),
      arm_data["validation"],
    )

  untrained_loss = validation_loss()
  result = train_inverse_model(
    network, trained_forward_model, arm_data["train"], arm_data["validation"], config, CPU
  )
  assert result.best_validation_loss < untrained_loss / 5
  assert validation_loss() == result.best_validation_loss  # the best weights are the ones kept


def test_inverse_training_leaves_the_forward_model_untouched(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  before = _state(trained_forward_model)
  train_inverse_model(
    _fresh_column(),
    trained_forward_model,
    arm_data["train"],
    arm_data["validation"],
    SHORT_RUN,
    CPU,
  )
  assert all(
    torch.equal(value, before[name]) for name, value in trained_forward_model.state_dict().items()
  )


def test_pose_term_changes_the_objective(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  network, windows = _fresh_column(), arm_data["validation"]
  with torch.no_grad():
    actions_only = inverse_model_loss(network, trained_forward_model, windows)
    with_poses = inverse_model_loss(network, trained_forward_model, windows, pose_loss_weight=1.0)
  assert with_poses > actions_only


@pytest.mark.parametrize(
  "make_model", [_fresh_column, lambda: VAELSTMInverse(14, 2, hidden_size=16)]
)
def test_same_seed_gives_identical_weights_and_another_seed_does_not(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel, make_model
) -> None:
  def train(seed: int) -> dict[str, torch.Tensor]:
    torch.manual_seed(0)
    model = make_model()
    config = dataclasses.replace(SHORT_RUN, seed=seed)
    train_inverse_model(
      model, trained_forward_model, arm_data["train"], arm_data["validation"], config, CPU
    )
    return _state(model)

  first, again, other = train(seed=1), train(seed=1), train(seed=2)
  assert all(torch.equal(first[name], again[name]) for name in first)
  assert not all(torch.equal(first[name], other[name]) for name in first)


def test_training_restores_the_callers_random_state_and_thread_count(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  network = _fresh_column()
  previous_threads = torch.get_num_threads()
  torch.set_num_threads(2)
  torch.manual_seed(123)
  expected_draw = torch.rand(3)
  torch.manual_seed(123)
  try:
    train_inverse_model(
      network,
      trained_forward_model,
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
    )
    assert torch.get_num_threads() == 2
  finally:
    torch.set_num_threads(previous_threads)
  assert torch.equal(torch.rand(3), expected_draw)


def test_every_epoch_is_reported_and_training_stops_after_patience_without_improvement(
  arm_data: dict[str, BabblingWindows],
) -> None:
  torch.manual_seed(0)
  forward_model = ForwardModel(actuation_size=2, hidden_size=8)
  reports = []
  # A learning rate this large makes the validation loss stop improving almost at once.
  config = ForwardTrainingConfig(max_epochs=40, patience=2, learning_rate=5.0)
  result = fit(
    forward_model,
    lambda windows: forward_model_loss(forward_model, windows),
    arm_data["train"],
    arm_data["validation"],
    config,
    CPU,
    reports.append,
  )
  assert result.stopped_early and result.epochs_run < 40
  assert reports == result.history and len(reports) == result.epochs_run
  assert result.epochs_run - 1 - result.best_epoch == config.patience
  assert min(report.validation_loss for report in reports) == result.best_validation_loss


def test_early_stopping_counts_epochs_since_the_best_loss() -> None:
  stopping = EarlyStopping(patience=2)
  decisions = []
  for epoch, loss in enumerate([3.0, 2.0, 2.5, 1.5, 1.7, 1.6]):
    improved = stopping.update(epoch, loss)
    decisions.append((improved, stopping.should_stop))
  assert decisions == [
    (True, False),
    (True, False),
    (False, False),
    (True, False),
    (False, False),
    (False, True),
  ]
  assert (stopping.best_epoch, stopping.best_loss) == (3, 1.5)


def test_a_model_without_trainable_weights_is_refused(arm_data: dict[str, BabblingWindows]) -> None:
  frozen = ForwardModel(actuation_size=2, hidden_size=8).freeze()
  with pytest.raises(ValueError, match="no trainable parameters"):
    fit(
      frozen,
      lambda windows: forward_model_loss(frozen, windows),
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
    )


def test_inverse_training_needs_a_frozen_forward_model(
  arm_data: dict[str, BabblingWindows],
) -> None:
  with pytest.raises(ValueError, match="frozen"):
    train_inverse_model(
      _fresh_column(),
      ForwardModel(actuation_size=2),
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
    )


def test_a_compiled_optimiser_step_prints_no_profiler_notice() -> None:
  """Dynamo skips the optimisers' profiler markers and says so once per process, a line that
  every worker of a compiled run printed; training filters it out."""
  torch._logging._internal.warning_once.cache_clear()  # Said already in this process?
  logger = logging.getLogger("torch._dynamo.variables.ctx_manager")
  said = io.StringIO()
  handler = logging.StreamHandler(said)  # Sees what passes the logger's own filters.
  logger.addHandler(handler)
  try:
    model = torch.nn.Linear(3, 1)
    optimizer = torch.optim.Adam(model.parameters())
    model(torch.ones(3)).sum().backward()
    fitting._compiled(optimizer.step)()
  finally:
    logger.removeHandler(handler)
  assert "Profiler record function" not in said.getvalue()


INVERSE_MODELS = {
  "smpl-column": lambda: _fresh_column(),
  **{
    cls.__name__: (lambda cls=cls: cls(inverse_input_size(6, 2), 2, hidden_size=8))
    for cls in (MLPInverse, LSTMInverse, VAELSTMInverse, BiLSTMInverse)
  },
}


def test_every_trainable_inverse_model_is_listed(inverse_model_classes: set[type]) -> None:
  # A ProgressiveColumn is a view of one column for acting; its network is what trains.
  listed = {type(make()) for make in INVERSE_MODELS.values()}
  assert listed == inverse_model_classes - {ProgressiveColumn}


@pytest.fixture
def compiled_functions(monkeypatch) -> list:
  """What `smpl.training` hands to torch.compile during the test (still compiled)."""
  handed, compiled = [], fitting._compiled

  def counting(function):
    handed.append(function)
    return compiled(function)

  monkeypatch.setattr(fitting, "_compiled", counting)
  return handed


@pytest.mark.parametrize("name", INVERSE_MODELS)
def test_every_model_compiles_to_the_eager_losses_or_says_it_cannot(
  name: str,
  short_arm_data: dict[str, BabblingWindows],
  trained_forward_model: ForwardModel,
  compiled_functions: list,
) -> None:
  """With compile asked, a model compiles on the CPU (its loss and optimiser step) if its
  `compiles_on_cpu` says it can, and trains eagerly otherwise: never a failed compile, which
  warns before falling back. Compiling changes only float rounding: the same training from the
  same weights lands on nearly the same losses (where Inductor draws random numbers as eager
  torch does; by default it draws the VAE's latent noise from a generator of its own). (Short
  windows: compiling unrolls a window's closed loop, and the properties do not depend on its
  length.)"""
  arm_data = short_arm_data
  losses = {}
  for compile_ in (False, True):
    torch.manual_seed(0)
    model = INVERSE_MODELS[name]()
    config = dataclasses.replace(SHORT_RUN, max_epochs=2, compile=compile_)
    with warnings.catch_warnings(), torch._inductor.config.patch(fallback_random=True):
      warnings.simplefilter("error", RuntimeWarning)  # "torch.compile failed" would raise.
      result = train_inverse_model(
        model, trained_forward_model, arm_data["train"], arm_data["validation"], config, CPU
      )
    losses[compile_] = [report.train_loss for report in result.history]
  assert len(compiled_functions) == (2 if getattr(model, "compiles_on_cpu", True) else 0)
  assert losses[True] == pytest.approx(losses[False], rel=1e-3)


def test_the_forward_model_trains_eagerly_on_the_cpu_without_a_warning(
  arm_data: dict[str, BabblingWindows], compiled_functions: list
) -> None:
  config = dataclasses.replace(ForwardTrainingConfig(), max_epochs=1, compile=True)
  with warnings.catch_warnings():
    warnings.simplefilter("error", RuntimeWarning)
    train_forward_model(
      ForwardModel(actuation_size=2, hidden_size=8),
      arm_data["train"],
      arm_data["validation"],
      config,
      CPU,
    )
  assert compiled_functions == []


def test_validation_leaves_out_the_aux_loss(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  torch.manual_seed(0)
  model = VAELSTMInverse(14, 2, hidden_size=16, kl_weight=10.0)  # A KL term that dominates.
  config = InverseTrainingConfig(max_epochs=1, patience=1)
  result = train_inverse_model(
    model, trained_forward_model, arm_data["train"], arm_data["validation"], config, CPU
  )

  def loss(include_aux_loss: bool) -> float:
    return evaluate_loss(
      model,
      lambda windows: inverse_model_loss(
        model, trained_forward_model, windows, include_aux_loss=include_aux_loss
      ),
      arm_data["validation"],
    )

  assert result.best_validation_loss == loss(include_aux_loss=False)
  assert loss(include_aux_loss=True) > result.best_validation_loss


def test_weight_decay_shrinks_the_weights(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  def weight_norm(weight_decay: float) -> float:
    network = _fresh_column()
    config = dataclasses.replace(SHORT_RUN, weight_decay=weight_decay)
    train_inverse_model(
      network, trained_forward_model, arm_data["train"], arm_data["validation"], config, CPU
    )
    return sum(parameter.square().sum().item() for parameter in network.parameters())

  assert weight_norm(weight_decay=1.0) < weight_norm(weight_decay=0.0)


def _zero_action_loss(windows: BabblingWindows) -> float:
  return float(torch.mean(windows.actions**2))


def test_a_training_that_does_not_diverge_is_untouched_by_restarts(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  def train(restart_diverged: bool) -> tuple[dict[str, torch.Tensor], fitting.TrainingResult]:
    network = _fresh_column()
    result = train_inverse_model(
      network,
      trained_forward_model,
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
      restart_diverged=restart_diverged,
    )
    return _state(network), result

  with warnings.catch_warnings():
    warnings.simplefilter("error")
    (plain, _), (guarded, result) = train(False), train(True)
  assert result.best_validation_loss < _zero_action_loss(arm_data["validation"])
  assert result.restarts == 0 and result.learning_rate is None
  assert all(torch.equal(plain[name], guarded[name]) for name in plain)


def test_a_diverged_training_starts_again_from_its_initial_weights_at_half_the_rate(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel, monkeypatch
) -> None:
  network = _fresh_column()
  initial = _state(network)
  zero_action = _zero_action_loss(arm_data["validation"])
  calls = []

  def diverging_then_converging(model, batch_loss, train, validation, config, *args, **kwargs):
    calls.append((config.learning_rate, _state(model)))
    with torch.no_grad():  # What a diverged training leaves behind.
      for parameter in model.parameters():
        parameter.add_(1.0)
    loss = 3 * zero_action if len(calls) < 3 else zero_action / 10
    blown_up = 100 * zero_action if len(calls) < 3 else loss
    return fitting.TrainingResult(
      0, loss, True, [fitting.EpochReport(0, blown_up, loss, loss, True, 0.1)]
    )

  monkeypatch.setattr(fitting, "fit", diverging_then_converging)
  with pytest.warns(UserWarning, match="training of seed 0 diverged") as caught:
    result = train_inverse_model(
      network,
      trained_forward_model,
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
      restart_diverged=True,
    )
  rate = SHORT_RUN.learning_rate
  assert [call[0] for call in calls] == [rate, rate / 2, rate / 4]
  assert all(
    torch.equal(state[name], initial[name]) for _, state in calls for name in initial
  )  # Every attempt starts afresh.
  assert len(caught) == 2 and "learning rate" in str(caught[0].message)
  assert (result.restarts, result.learning_rate) == (2, rate / 4)
  assert result.best_validation_loss == zero_action / 10


def test_a_training_that_keeps_diverging_gives_up_with_a_warning(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  config = dataclasses.replace(SHORT_RUN, max_epochs=1, learning_rate=1e4)
  with pytest.warns(UserWarning) as caught:
    result = train_inverse_model(
      MLPInverse(inverse_input_size(6, 2), 2),
      trained_forward_model,
      arm_data["train"],
      arm_data["validation"],
      config,
      CPU,
      restart_diverged=True,
    )
  messages = [str(warning.message) for warning in caught]
  assert (
    sum("diverged (best" in message and "still" not in message for message in messages)
    == training.DIVERGENCE_RESTARTS
  )
  assert any("still diverged" in message for message in messages)
  assert result.restarts == training.DIVERGENCE_RESTARTS
  assert result.learning_rate == 1e4 / 2**training.DIVERGENCE_RESTARTS
  assert result.best_validation_loss >= _zero_action_loss(arm_data["validation"])


def test_a_short_training_that_has_not_learned_yet_is_not_diverged(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel, monkeypatch
) -> None:
  zero_action = _zero_action_loss(arm_data["validation"])
  calls = []

  def barely_trained(model, batch_loss, train, validation, config, *args, **kwargs):
    calls.append(config.learning_rate)
    return fitting.TrainingResult(
      0,
      1.1 * zero_action,
      False,
      [fitting.EpochReport(0, 1.5 * zero_action, 1.1 * zero_action, 1.1 * zero_action, True, 0.1)],
    )

  monkeypatch.setattr(fitting, "fit", barely_trained)
  with warnings.catch_warnings():
    warnings.simplefilter("error")
    result = train_inverse_model(
      _fresh_column(),
      trained_forward_model,
      arm_data["train"],
      arm_data["validation"],
      SHORT_RUN,
      CPU,
      restart_diverged=True,
    )
  assert calls == [SHORT_RUN.learning_rate] and result.restarts == 0
