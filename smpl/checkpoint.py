"""Saving and loading trained models with their configuration and normalisation statistics.

A checkpoint holds the model's weights, the configuration dataclass it was built and trained with
(stored as a dict), the normalisation statistics of its data (arrays, passed through untouched)
and a sha256 of the weights and statistics (names, dtypes, shapes, bytes). Files are written
atomically, so a crash never leaves a half-written checkpoint under the real name. Loading
refuses, with a one-line `CheckpointError` naming the file, a file that is not a complete, intact
checkpoint or whose configuration differs from the one expected, and leaves the model untouched.
Files written before the hash was added (no `sha256` field) load as before, unverified. A cache
reads its checkpoints through `smpl.files.read_cached`, which turns any refusal into one warning
and trains the model again.
"""

from __future__ import annotations

from collections.abc import Mapping
import dataclasses
import hashlib
import io
import os
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from smpl.files import first_line
from smpl.files import write_atomically

_FORMAT = "softbench-smpl-checkpoint"
"""Marks a file as one of ours."""
_FORMAT_VERSION = 1
"""Bumped whenever the layout of the stored dict changes."""
_FIELDS = frozenset({"format", "version", "config_type", "config", "state_dict", "normalisation"})
"""The fields of every checkpoint; those written since the hash was added also have `sha256`."""
_HASH_FIELD = "sha256"


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
  state_dict = {name: tensor.detach().cpu() for name, tensor in model.state_dict().items()}
  arrays = {
    name: torch.from_numpy(np.array(values)) for name, values in (normalisation or {}).items()
  }
  payload = {
    "format": _FORMAT,
    "version": _FORMAT_VERSION,
    "config_type": type(config).__qualname__,
    "config": dataclasses.asdict(config),
    "state_dict": state_dict,
    "normalisation": arrays,
    _HASH_FIELD: _content_sha256(state_dict, arrays),
  }
  save_atomically(path, payload)


def save_atomically(path: Path, payload: Any) -> None:
  """`torch.save(payload)` to `path` through `write_atomically`."""
  buffer = io.BytesIO()
  torch.save(payload, buffer)
  write_atomically(path, buffer.getvalue())


def load_checkpoint(
  path: str | os.PathLike[str],
  model: nn.Module,
  config: Any,
  map_location: torch.device | None = None,
) -> dict[str, np.ndarray]:
  """Loads the weights in `path` into `model` and returns the normalisation arrays.

  `config` is the dataclass the caller built `model` from; the stored one must equal it.
  Raises FileNotFoundError if there is no file, and a one-line CheckpointError, leaving `model`
  untouched, if the file is unreadable, truncated, corrupt (its sha256 differs), not a
  checkpoint, holds another configuration, or holds weights that do not fit `model`.
  """
  path = Path(path)
  try:
    content = path.read_bytes()
  except FileNotFoundError:
    raise
  except OSError as error:  # A folder, no permission, ...
    raise CheckpointError(f"{path}: unreadable: {first_line(error)}") from error
  try:
    payload = torch.load(io.BytesIO(content), map_location=map_location, weights_only=True)
  except Exception as error:
    # A damaged file raises nearly anything: UnpicklingError, RuntimeError, EOFError,
    # KeyError, IndexError, TypeError, ...
    raise CheckpointError(
      f"{path}: not a readable checkpoint (truncated or corrupt): {_described(error)}"
    ) from error
  try:
    state_dict, normalisation = _checked(payload, model, config)
    model.load_state_dict(state_dict)
  except CheckpointError as error:
    raise CheckpointError(f"{path}: {error}") from error
  except Exception as error:  # A field of the wrong type or shape: a damaged file.
    raise CheckpointError(f"{path}: malformed checkpoint: {_described(error)}") from error
  return {name: tensor.cpu().numpy() for name, tensor in normalisation.items()}


def _checked(
  payload: Any, model: nn.Module, config: Any
) -> tuple[dict[str, torch.Tensor], dict[str, torch.Tensor]]:
  """The state dict and normalisation tensors of a loaded checkpoint, once they have passed
  every check (module docstring); a CheckpointError (not naming the file) otherwise."""
  if not isinstance(payload, dict) or payload.get("format") != _FORMAT:
    raise CheckpointError("not a softbench SMPL checkpoint")
  if payload["version"] != _FORMAT_VERSION:
    raise CheckpointError(
      f"checkpoint format version {payload['version']}, this code reads version {_FORMAT_VERSION}"
    )
  if payload.keys() - {_HASH_FIELD} != _FIELDS:
    raise CheckpointError(f"fields {sorted(map(str, payload))} are not a checkpoint's")
  state_dict, normalisation = payload["state_dict"], payload["normalisation"]
  for name, tensors in (("state_dict", state_dict), ("normalisation", normalisation)):
    if not isinstance(tensors, dict) or not all(
      isinstance(key, str) and isinstance(value, torch.Tensor) for key, value in tensors.items()
    ):
      raise CheckpointError(f"{name} is not a dict of named tensors (corrupt)")
  if _HASH_FIELD in payload and payload[_HASH_FIELD] != _content_sha256(state_dict, normalisation):
    raise CheckpointError("weights or normalisation differ from their sha256 (corrupt)")
  expected_type = type(config).__qualname__
  if payload["config_type"] != expected_type:
    raise CheckpointError(f"holds a {payload['config_type']}, expected a {expected_type}")
  if not isinstance(payload["config"], dict):
    raise CheckpointError("its configuration is not a dict (corrupt)")
  differences = _config_differences(payload["config"], dataclasses.asdict(config))
  if differences:
    raise CheckpointError(f"configuration differs: {differences}")
  misfit = _misfit(state_dict, model.state_dict())
  if misfit:
    raise CheckpointError(f"weights do not fit the model: {misfit}")
  return state_dict, normalisation


def _misfit(stored: dict[str, torch.Tensor], expected: dict[str, torch.Tensor]) -> str:
  """Why `stored` weights cannot be loaded where `expected` ones are, or '' if they can."""
  if stored.keys() != expected.keys():
    missing, unexpected = sorted(expected.keys() - stored), sorted(stored.keys() - expected)
    return f"missing {missing[:3]}, unexpected {unexpected[:3]}"
  for name, tensor in stored.items():
    wanted = expected[name]
    if tensor.shape != wanted.shape or tensor.dtype != wanted.dtype:
      return (
        f"{name} is {tensor.dtype} {tuple(tensor.shape)}, "
        f"the model's {wanted.dtype} {tuple(wanted.shape)}"
      )
  return ""


def _content_sha256(
  state_dict: Mapping[str, torch.Tensor], normalisation: Mapping[str, torch.Tensor]
) -> str:
  """The sha256 of the weights and normalisation arrays: names, dtypes, shapes and values."""
  digest = hashlib.sha256()
  for group, tensors in (("state_dict", state_dict), ("normalisation", normalisation)):
    for name in sorted(tensors):
      array = np.ascontiguousarray(tensors[name].detach().cpu().numpy())
      digest.update(f"{group}/{name}|{array.dtype.str}|{array.shape}|".encode())
      digest.update(array.tobytes())
  return digest.hexdigest()


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


def _described(error: BaseException) -> str:
  """'Type: first line', as a bare message ('101' of a KeyError) says little."""
  return f"{type(error).__name__}: {first_line(error)}"
