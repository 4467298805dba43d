"""Saving and loading trained models with their configuration and normalisation statistics.

A checkpoint holds the model's weights, the configuration dataclass it was built and trained with
(stored as a dict) and the normalisation statistics of its data (arrays, passed through untouched).
Files are written atomically, so a crash never leaves a half-written checkpoint under the real
name. Loading refuses, with a one-line `CheckpointError` naming the file, a file that is not a
complete checkpoint or whose configuration differs from the one expected.
"""

from __future__ import annotations

import dataclasses
import io
import os
import pickle
import tempfile
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

_FORMAT = "softbench-smpl-checkpoint"
"""Marks a file as one of ours."""
_FORMAT_VERSION = 1
"""Bumped whenever the layout of the stored dict changes."""
_UNREADABLE = (RuntimeError, EOFError, pickle.UnpicklingError, zipfile.BadZipFile, ValueError)
"""What torch.load raises for truncated or corrupt files."""


class CheckpointError(ValueError):
    """A checkpoint file is unreadable or does not match what the caller expects."""


def save_checkpoint(
    path: str | os.PathLike[str],
    model: nn.Module,
    config: Any,
    normalisation: Mapping[str, np.ndarray] | None = None,
) -> None:
    """Writes `model`'s weights, the dataclass `config` and `normalisation` arrays to `path`."""
    path = Path(path)
    payload = {
        "format": _FORMAT,
        "version": _FORMAT_VERSION,
        "config_type": type(config).__qualname__,
        "config": dataclasses.asdict(config),
        "state_dict": {name: tensor.detach().cpu() for name, tensor in model.state_dict().items()},
        "normalisation": {
            name: torch.from_numpy(np.array(values))
            for name, values in (normalisation or {}).items()
        },
    }
    save_atomically(path, payload)


def save_atomically(path: Path, payload: Any) -> None:
    """`torch.save(payload)` to `path` through a temporary file in its folder and a rename, so a
    crash never leaves half a file under the real name."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as file:
            torch.save(payload, file)
            file.flush()
            os.fsync(file.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def load_checkpoint(
    path: str | os.PathLike[str],
    model: nn.Module,
    config: Any,
    map_location: torch.device | None = None,
) -> dict[str, np.ndarray]:
    """Loads the weights in `path` into `model` and returns the normalisation arrays.

    `config` is the dataclass the caller built `model` from; the stored one must equal it.
    Raises CheckpointError if the file is truncated, corrupt, not a checkpoint, holds another
    configuration, or holds weights that do not fit `model`.
    """
    path = Path(path)
    content = path.read_bytes()  # a missing or unreadable file raises its own OSError
    try:
        payload = torch.load(io.BytesIO(content), map_location=map_location, weights_only=True)
    except _UNREADABLE as error:
        raise CheckpointError(
            f"{path}: not a readable checkpoint (truncated or corrupt): {_first_line(error)}"
        ) from error
    if not isinstance(payload, dict) or payload.get("format") != _FORMAT:
        raise CheckpointError(f"{path}: not a softbench SMPL checkpoint")
    if payload["version"] != _FORMAT_VERSION:
        raise CheckpointError(
            f"{path}: checkpoint format version {payload['version']}, "
            f"this code reads version {_FORMAT_VERSION}"
        )
    expected_type = type(config).__qualname__
    if payload["config_type"] != expected_type:
        raise CheckpointError(
            f"{path}: holds a {payload['config_type']}, expected a {expected_type}"
        )
    differences = _config_differences(payload["config"], dataclasses.asdict(config))
    if differences:
        raise CheckpointError(f"{path}: configuration differs: {differences}")
    try:
        model.load_state_dict(payload["state_dict"])
    except RuntimeError as error:
        raise CheckpointError(
            f"{path}: weights do not fit the model: {_first_line(error)}"
        ) from error
    return {name: tensor.cpu().numpy() for name, tensor in payload["normalisation"].items()}


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


_MISSING = _Missing()


def _config_differences(stored: dict[str, Any], expected: dict[str, Any]) -> str:
    """'field (file X, expected Y)' for every field that differs, comma separated; '' if none."""
    return ", ".join(
        f"{name} (file {stored.get(name, _MISSING)!r}, expected {expected.get(name, _MISSING)!r})"
        for name in sorted(stored.keys() | expected.keys())
        if stored.get(name, _MISSING) != expected.get(name, _MISSING)
    )


def _first_line(error: BaseException) -> str:
    lines = str(error).strip().splitlines()
    return lines[0] if lines else type(error).__name__
