import torch

from smpl.fitting import evaluate_loss
from smpl.forward_model import ForwardModel
from smpl.training import forward_model_loss
from smpl.windows import BabblingWindows


def test_stepwise_prediction_matches_the_whole_sequence() -> None:
  torch.manual_seed(0)
  model = ForwardModel(actuation_size=3, hidden_size=16)
  previous, current, actuation = torch.randn(4, 9, 6), torch.randn(4, 9, 6), torch.randn(4, 9, 3)
  sequence = model(previous, current, actuation)
  state = model.initial_state(4)
  stepped = []
  for step in range(9):
    pose, state = model.step(previous[:, step], current[:, step], actuation[:, step], state)
    stepped.append(pose)
  torch.testing.assert_close(torch.stack(stepped, dim=1), sequence, rtol=0, atol=1e-6)


def test_frozen_model_has_no_trainable_weights_but_passes_gradients_to_its_inputs() -> None:
  torch.manual_seed(0)
  model = ForwardModel(actuation_size=2, hidden_size=16).freeze()
  assert model.is_frozen and not model.training
  actuation = torch.randn(4, 5, 2, requires_grad=True)
  model(torch.randn(4, 5, 6), torch.randn(4, 5, 6), actuation).sum().backward()
  assert actuation.grad is not None and actuation.grad.abs().sum() > 0
  assert all(parameter.grad is None for parameter in model.parameters())


def test_trained_model_predicts_the_synthetic_arm_far_better_than_untrained(
  arm_data: dict[str, BabblingWindows], trained_forward_model: ForwardModel
) -> None:
  torch.manual_seed(0)
  untrained = ForwardModel(actuation_size=2)
  validation = arm_data["validation"]
  untrained_loss = evaluate_loss(untrained, lambda w: forward_model_loss(untrained, w), validation)
  trained_loss = evaluate_loss(
    trained_forward_model, lambda w: forward_model_loss(trained_forward_model, w), validation
  )
  assert trained_loss < untrained_loss / 10
