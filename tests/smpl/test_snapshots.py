"""Resumable training (smpl.snapshots): a stopped fit ends as if it had never stopped."""

import pytest
import torch

from smpl import files
from smpl import fitting
from smpl import snapshots
from smpl import training
from smpl.baselines import VAELSTMInverse
from smpl.forward_model import ForwardModel
from smpl.windows import BabblingWindows
from smpl.windows import inverse_input_size

CPU = torch.device("cpu")
POSE, ACTION = 6, 2
FORWARD = training.ForwardTrainingConfig(max_epochs=6, patience=6)
INVERSE = training.InverseTrainingConfig(max_epochs=5, patience=5)


class Interrupted(Exception):
  pass


def windows(count, seed):
  generator = torch.Generator().manual_seed(seed)
  return BabblingWindows(
    torch.rand(count, 17, POSE, generator=generator),
    torch.rand(count, 15, ACTION, generator=generator),
    torch.zeros(count, 15, 0),
  )


TRAIN, VALIDATION = windows(64, 1), windows(16, 2)


def forward_model():
  with fitting.seeded(0, CPU):
    return ForwardModel(ACTION, POSE)


def trained_forward_model():
  model = forward_model()
  training.train_forward_model(model, TRAIN, VALIDATION, FORWARD, CPU)
  return model.freeze()


def train_forward(model, on_epoch_end=None, config=FORWARD):
  return training.train_forward_model(model, TRAIN, VALIDATION, config, CPU, on_epoch_end)


def train_vae(model, on_epoch_end=None, config=INVERSE):
  # The VAE draws latent noise from torch's generator: resuming must restore it too.
  return training.train_inverse_model(
    model, FROZEN_FORWARD, TRAIN, VALIDATION, config, CPU, on_epoch_end
  )


def vae():
  with fitting.seeded(0, CPU):
    return VAELSTMInverse(inverse_input_size(POSE, ACTION), ACTION)


FROZEN_FORWARD = trained_forward_model()
MODELS = {"forward": (forward_model, train_forward), "vae-lstm": (vae, train_vae)}


def stop_at(epoch):
  def on_epoch_end(report):
    if report.epoch == epoch:
      raise Interrupted

  return on_epoch_end


def same_weights(first, second):
  return all(
    torch.equal(a, b) for a, b in zip(first.state_dict().values(), second.state_dict().values())
  )


@pytest.fixture(autouse=True)
def snapshot_every_epoch(monkeypatch):
  monkeypatch.setattr(snapshots, "SAVE_INTERVAL_S", 0.0)


@pytest.mark.parametrize("kind", MODELS)
def test_stopped_fit_resumes_to_the_same_weights_and_history(kind, tmp_path):
  make, train = MODELS[kind]
  uninterrupted = make()
  expected = train(uninterrupted)
  with pytest.raises(Interrupted), snapshots.resumable(tmp_path):
    train(make(), stop_at(2))
  assert [path.name for path in tmp_path.iterdir()] == ["fit-1.pt"]
  resumed, epochs = make(), []
  with snapshots.resumable(tmp_path):
    result = train(resumed, lambda report: epochs.append((report.epoch, report.resumed)))
  # The three epochs run before the stop are handed on again first, marked as such.
  assert epochs == [(epoch, epoch <= 2) for epoch in range(len(expected.history))]
  assert same_weights(uninterrupted, resumed)
  assert [r.validation_loss for r in result.history] == [
    r.validation_loss for r in expected.history
  ]
  assert (result.best_epoch, result.best_validation_loss) == (
    expected.best_epoch,
    expected.best_validation_loss,
  )


def test_finished_fit_returns_its_result_without_training(tmp_path, monkeypatch):
  with snapshots.resumable(tmp_path):
    first = forward_model()
    expected = train_forward(first)
  monkeypatch.setattr(fitting, "_train_epoch", lambda *args: pytest.fail("trained again"))
  snapshot = tmp_path / "fit-1.pt"
  written = snapshot.stat().st_mtime_ns
  again = forward_model()
  with snapshots.resumable(tmp_path):
    result = train_forward(again)
  assert same_weights(first, again) and not again.training
  assert result.history == expected.history
  assert snapshot.stat().st_mtime_ns == written  # Nothing new to save.


def test_each_fit_of_a_run_keeps_its_own_snapshot(tmp_path):
  with snapshots.resumable(tmp_path):
    train_forward(forward_model())
    train_vae(vae())
  assert sorted(path.name for path in tmp_path.iterdir()) == ["fit-1.pt", "fit-2.pt"]


def test_no_snapshot_outside_resumable(tmp_path, monkeypatch):
  monkeypatch.chdir(tmp_path)
  train_forward(forward_model())
  assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("spoil", ["other config", "truncated", "not a snapshot"])
def test_unusable_snapshot_is_ignored_with_a_warning(spoil, tmp_path):
  with pytest.raises(Interrupted), snapshots.resumable(tmp_path):
    train_forward(forward_model(), stop_at(1))
  snapshot = tmp_path / "fit-1.pt"
  config = FORWARD
  if spoil == "other config":
    config = training.ForwardTrainingConfig(max_epochs=6, patience=6, learning_rate=2e-3)
  elif spoil == "truncated":
    snapshot.write_bytes(snapshot.read_bytes()[:500])
  else:
    torch.save({"weights": torch.zeros(3)}, snapshot)
  fresh = forward_model()
  expected = train_forward(fresh, config=config)
  resumed = forward_model()
  with (
    pytest.warns(files.CorruptFileWarning, match="training that model from the start"),
    snapshots.resumable(tmp_path),
  ):
    result = train_forward(resumed, config=config)
  assert same_weights(fresh, resumed)
  assert result.history[0].validation_loss == expected.history[0].validation_loss


@pytest.mark.parametrize("content", ["object", "hello"])
def test_an_unreadable_snapshot_is_reported_in_one_line(content, tmp_path):
  # torch refuses a pickled object with a message of several paragraphs; b"hello" makes it raise
  # KeyError: 101.
  snapshot = tmp_path / "fit-1.pt"
  if content == "object":
    torch.save({"format": "softbench-smpl-fit-snapshot", "state": Interrupted()}, snapshot)
  else:
    snapshot.write_bytes(b"hello")
  with pytest.warns(files.CorruptFileWarning) as caught:
    assert snapshots.load(snapshot, "fingerprint") is None
  (warning,) = caught
  message = str(warning.message)
  assert str(snapshot) in message and "from the start" in message
  assert "\n" not in message and "\x1b" not in message
