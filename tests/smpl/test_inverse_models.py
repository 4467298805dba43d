"""Properties every inverse model must have, checked over all of them at once."""

from collections.abc import Callable

import pytest
import torch

from smpl.baselines import BiLSTMInverse
from smpl.baselines import LSTMInverse
from smpl.baselines import MLPInverse
from smpl.baselines import VAELSTMInverse
from smpl.inverse import InverseModel
from smpl.progressive import ProgressiveLSTM

INPUT_SIZE, ACTION_SIZE = 16, 4
BATCH, STEPS = 3, 20  # longer than the Bi-LSTM window, to exercise its sliding


def _two_column_smpl() -> ProgressiveLSTM:
  network = ProgressiveLSTM(hidden_size=8)
  network.add_column(INPUT_SIZE - 2, ACTION_SIZE - 2)
  network.add_column(INPUT_SIZE, ACTION_SIZE)
  return network


INVERSE_MODELS: dict[str, Callable[[], InverseModel]] = {
  "smpl": _two_column_smpl,
  "smpl-first-column": lambda: _two_column_smpl().column_model(0),
  "mlp": lambda: MLPInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=16),
  "lstm": lambda: LSTMInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=8),
  "vae-lstm": lambda: VAELSTMInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=8, latent_size=3),
  "bi-lstm": lambda: BiLSTMInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=8, window=6),
}


def test_every_inverse_model_is_listed(inverse_model_classes: set[type]) -> None:
  assert {type(make()) for make in INVERSE_MODELS.values()} == inverse_model_classes


@pytest.fixture(params=sorted(INVERSE_MODELS))
def model(request: pytest.FixtureRequest) -> InverseModel:
  torch.manual_seed(0)
  return INVERSE_MODELS[request.param]().eval()


def _stepwise(model: InverseModel, inputs: torch.Tensor) -> torch.Tensor:
  state = model.initial_state(inputs.shape[0])
  actions = []
  for step_inputs in inputs.unbind(1):
    step = model.step(step_inputs, state)
    actions.append(step.action)
    state = step.state
  return torch.stack(actions, dim=1)


def test_stepwise_control_matches_the_whole_sequence(model: InverseModel) -> None:
  inputs = torch.randn(BATCH, STEPS, model.input_size)
  sequence, _ = model(inputs)
  assert sequence.shape == (BATCH, STEPS, model.action_size)
  torch.testing.assert_close(_stepwise(model, inputs), sequence, rtol=0, atol=1e-5)


def test_an_action_never_depends_on_later_inputs(model: InverseModel) -> None:
  inputs = torch.randn(BATCH, STEPS, model.input_size)
  changed_from = 8
  changed = inputs.clone()
  changed[:, changed_from:] += 1.0
  before, _ = model(inputs)
  after, _ = model(changed)
  assert torch.equal(after[:, :changed_from], before[:, :changed_from])
  assert not torch.equal(after[:, changed_from:], before[:, changed_from:])


def test_aux_loss_is_a_scalar_that_only_the_vae_uses(model: InverseModel) -> None:
  model.train()
  _, aux_loss = model(torch.randn(BATCH, STEPS, model.input_size))
  assert aux_loss.shape == ()
  assert (aux_loss.item() > 0) == isinstance(model, VAELSTMInverse)


def test_bilstm_forgets_inputs_older_than_its_window() -> None:
  torch.manual_seed(0)
  model = BiLSTMInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=8, window=6).eval()
  inputs = torch.randn(BATCH, STEPS, INPUT_SIZE)
  changed = inputs.clone()
  changed[:, 0] += 1.0
  before, _ = model(inputs)
  after, _ = model(changed)
  assert not torch.equal(after[:, 5], before[:, 5])  # step 5's window is steps 0..5
  torch.testing.assert_close(after[:, 6:], before[:, 6:], rtol=0, atol=1e-6)


def test_vae_samples_its_latent_in_training_and_uses_the_mean_in_eval() -> None:
  torch.manual_seed(0)
  model = VAELSTMInverse(INPUT_SIZE, ACTION_SIZE, hidden_size=8, latent_size=3)
  inputs = torch.randn(BATCH, STEPS, INPUT_SIZE)
  model.train()
  assert not torch.equal(model(inputs)[0], model(inputs)[0])
  model.eval()
  assert torch.equal(model(inputs)[0], model(inputs)[0])
