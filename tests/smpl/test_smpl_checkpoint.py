import dataclasses
from pathlib import Path

import numpy as np
import pytest
import torch

from smpl.checkpoint import CheckpointError
from smpl.checkpoint import load_checkpoint
from smpl.checkpoint import save_checkpoint
from smpl.progressive import ProgressiveLSTM


def _network() -> ProgressiveLSTM:
  torch.manual_seed(0)
  network = ProgressiveLSTM(hidden_size=8)
  network.add_column(14, 2)
  network.add_column(16, 4)
  return network


NORMALISATION = {"pose_low": np.linspace(-1.0, 0.0, 6), "action_high": np.ones(4, dtype=np.float32)}


def _saved(tmp_path: Path) -> tuple[Path, ProgressiveLSTM]:
  network = _network()
  path = tmp_path / "smpl.pt"
  save_checkpoint(path, network, network.config, NORMALISATION)
  return path, network


def test_round_trip_gives_identical_actions_and_normalisation(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  restored = ProgressiveLSTM.from_config(network.config)
  normalisation = load_checkpoint(path, restored, network.config)

  inputs = torch.randn(3, 15, 16)
  for column in range(network.num_columns):
    column_inputs = inputs[..., : network.columns[column].input_size]
    assert torch.equal(restored(column_inputs, column)[0], network(column_inputs, column)[0])
  assert normalisation.keys() == NORMALISATION.keys()
  for name, values in NORMALISATION.items():
    assert normalisation[name].dtype == values.dtype
    np.testing.assert_array_equal(normalisation[name], values)
  assert [path.name] == [entry.name for entry in tmp_path.iterdir()]  # no temporary file left


def test_truncated_file_raises_a_one_line_error_naming_it(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  content = path.read_bytes()
  path.write_bytes(content[: len(content) // 2])
  with pytest.raises(CheckpointError, match="truncated or corrupt") as raised:
    load_checkpoint(path, _network(), network.config)
  assert str(path) in str(raised.value) and "\n" not in str(raised.value)


def test_file_that_is_not_a_checkpoint_is_refused(tmp_path: Path) -> None:
  path = tmp_path / "notes.pt"
  path.write_text("not a checkpoint")
  with pytest.raises(CheckpointError, match=str(path)):
    load_checkpoint(path, _network(), _network().config)
  torch.save({"weights": torch.zeros(2)}, path)
  with pytest.raises(CheckpointError, match="not a softbench SMPL checkpoint"):
    load_checkpoint(path, _network(), _network().config)


def test_mismatched_config_names_the_differing_field(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  other_config = dataclasses.replace(network.config, hidden_size=16)
  with pytest.raises(CheckpointError, match=r"hidden_size \(file 8, expected 16\)") as raised:
    load_checkpoint(path, ProgressiveLSTM.from_config(other_config), other_config)
  assert str(path) in str(raised.value) and "\n" not in str(raised.value)


def test_weights_that_do_not_fit_the_model_are_refused(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  smaller = ProgressiveLSTM(hidden_size=8)
  smaller.add_column(14, 2)
  with pytest.raises(CheckpointError, match="weights do not fit"):
    load_checkpoint(path, smaller, network.config)


def test_a_failed_save_keeps_the_previous_checkpoint(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  content = path.read_bytes()

  @dataclasses.dataclass
  class Unsaveable:
    callback: object = lambda: None  # noqa: E731 - pickling a lambda fails mid-save

  with pytest.raises(AttributeError, match="pickle"):
    save_checkpoint(path, network, Unsaveable())
  assert path.read_bytes() == content
  assert [path.name] == [entry.name for entry in tmp_path.iterdir()]


def test_missing_file_raises_file_not_found(tmp_path: Path) -> None:
  with pytest.raises(FileNotFoundError):
    load_checkpoint(tmp_path / "absent.pt", _network(), _network().config)


def _assert_one_line_naming(error: BaseException, path: Path) -> None:
  assert isinstance(error, CheckpointError)
  assert str(path) in str(error) and "\n" not in str(error)


def _weights(network: torch.nn.Module) -> dict[str, torch.Tensor]:
  return {name: tensor.clone() for name, tensor in network.state_dict().items()}


def _same(first: dict[str, torch.Tensor], second: dict[str, torch.Tensor]) -> bool:
  return first.keys() == second.keys() and all(torch.equal(first[k], second[k]) for k in first)


@pytest.mark.parametrize("content", [b"hello", b"", b"PK\x03\x04" + bytes(40)])
def test_bytes_that_are_no_checkpoint_give_a_one_line_error(tmp_path: Path, content) -> None:
  # b"hello" used to escape from torch.load as KeyError: 101.
  path = tmp_path / "smpl.pt"
  path.write_bytes(content)
  with pytest.raises(CheckpointError) as raised:
    load_checkpoint(path, _network(), _network().config)
  _assert_one_line_naming(raised.value, path)


def test_a_folder_at_the_path_gives_a_one_line_error(tmp_path: Path) -> None:
  path = tmp_path / "smpl.pt"
  (path / "inside").mkdir(parents=True)
  with pytest.raises(CheckpointError) as raised:
    load_checkpoint(path, _network(), _network().config)
  _assert_one_line_naming(raised.value, path)
  assert (path / "inside").is_dir()  # Reading alone changes nothing (caches: smpl.files).


def test_a_flipped_byte_in_the_weights_fails_the_hash(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  content = bytearray(path.read_bytes())
  state = network.state_dict()
  values = state[max(state, key=lambda name: state[name].numel())].numpy().tobytes()
  offset = bytes(content).find(values)
  assert offset > 0 and bytes(content).find(values, offset + 1) == -1
  content[offset + 5] ^= 0x01  # One bit of one weight's mantissa.
  path.write_bytes(bytes(content))
  untouched = _network()
  before = _weights(untouched)
  with pytest.raises(CheckpointError, match="differ from their sha256") as raised:
    load_checkpoint(path, untouched, network.config)
  _assert_one_line_naming(raised.value, path)
  assert _same(_weights(untouched), before)  # A refused file leaves the model as it was.


def test_a_flipped_byte_in_the_normalisation_fails_the_hash(tmp_path: Path) -> None:
  path, network = _saved(tmp_path)
  content = bytearray(path.read_bytes())
  offset = bytes(content).find(NORMALISATION["pose_low"].tobytes())
  assert offset > 0
  content[offset + 3] ^= 0x10
  path.write_bytes(bytes(content))
  with pytest.raises(CheckpointError, match="sha256"):
    load_checkpoint(path, _network(), network.config)


def test_a_checkpoint_written_before_the_hash_still_loads(tmp_path: Path) -> None:
  # Cached checkpoints of the old layout (no sha256 field, same format version) stay valid.
  path, network = _saved(tmp_path)
  payload = torch.load(path, weights_only=True)
  assert isinstance(payload.pop("sha256"), str)
  torch.save(payload, path)
  restored = ProgressiveLSTM.from_config(network.config)
  normalisation = load_checkpoint(path, restored, network.config)
  assert _same(_weights(restored), _weights(network))
  np.testing.assert_array_equal(normalisation["pose_low"], NORMALISATION["pose_low"])


def test_an_unknown_field_is_refused(tmp_path: Path) -> None:
  # E.g. the hash field's name damaged: the file must not pass as an unverified old one.
  path, network = _saved(tmp_path)
  payload = torch.load(path, weights_only=True)
  payload["sha257"] = payload.pop("sha256")
  torch.save(payload, path)
  with pytest.raises(CheckpointError, match="not a checkpoint's"):
    load_checkpoint(path, _network(), network.config)


def test_damaged_checkpoints_are_refused_or_load_unchanged(tmp_path: Path) -> None:
  """Truncations and one-byte changes all over the file: each gives a one-line CheckpointError
  or (a byte that nothing reads) the saved weights and normalisation, never anything else."""
  path, network = _saved(tmp_path)
  intact = path.read_bytes()
  expected = _weights(network)
  damaged = [intact[:length] for length in range(0, len(intact), max(1, len(intact) // 60))]
  for offset in range(0, len(intact), max(1, len(intact) // 300)):
    flipped = bytearray(intact)
    flipped[offset] ^= 0xFF
    damaged.append(bytes(flipped))
  refused = 0
  for content in damaged:
    path.write_bytes(content)
    model = _network()
    try:
      normalisation = load_checkpoint(path, model, network.config)
    except CheckpointError as error:
      _assert_one_line_naming(error, path)
      refused += 1
      continue
    assert _same(_weights(model), expected)
    for name, values in NORMALISATION.items():
      np.testing.assert_array_equal(normalisation[name], values)
  assert refused > len(damaged) // 2
