import dataclasses
from pathlib import Path

import numpy as np
import pytest
import torch

from smpl.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
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
