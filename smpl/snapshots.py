"""Resumable training: `smpl.fitting.fit` keeps its state in a snapshot file and resumes from it.

Inside `with resumable(folder):` the n-th call of `fit` keeps its state in `folder/fit-<n>.pt`,
saved atomically at most every `SAVE_INTERVAL_S` seconds and when it ends. A training run calls
`fit` in the same order every time (forward models, then inverse columns), so after an
interruption each call finds its own snapshot again: a fit that had finished returns its result
at once, one that was under way goes on from its last saved epoch and ends with the same weights,
to the bit, as if it had never stopped. A snapshot that does not match its call (another config,
other data, other initial weights) or cannot be read is ignored, with a warning, and that fit
starts over. Outside `resumable`, `fit` keeps no snapshots.
"""

from __future__ import annotations

from collections.abc import Iterator
import contextlib
import contextvars
import os
from pathlib import Path
import shutil
from typing import Any

import torch

from smpl.checkpoint import save_atomically
from smpl.files import read_cached

SAVE_INTERVAL_S = 30.0
"""Least wall time (s) between two snapshots of a fit under way."""
_FORMAT = "softbench-smpl-fit-snapshot"


class _Sequence:
  """The snapshot folder and how many fits have taken a snapshot file from it."""

  def __init__(self, folder: Path) -> None:
    self.folder = folder
    self.calls = 0


_ACTIVE: contextvars.ContextVar[_Sequence | None] = contextvars.ContextVar(
  "smpl_snapshots", default=None
)


@contextlib.contextmanager
def resumable(folder: str | os.PathLike[str]) -> Iterator[None]:
  """Makes every `fit` inside the block keep a snapshot under `folder` (module docstring)."""
  token = _ACTIVE.set(_Sequence(Path(folder)))
  try:
    yield
  finally:
    _ACTIVE.reset(token)


def next_path() -> Path | None:
  """The snapshot file of the `fit` call now starting, or None outside `resumable`."""
  sequence = _ACTIVE.get()
  if sequence is None:
    return None
  sequence.calls += 1
  return sequence.folder / f"fit-{sequence.calls}.pt"


def save(path: Path, fingerprint: str, state: dict[str, Any]) -> None:
  """Writes `state` (tensors, numbers, lists) to `path` through a temporary file and a rename."""
  save_atomically(path, {"format": _FORMAT, "fingerprint": fingerprint, "state": state})


def load(path: Path, fingerprint: str) -> dict[str, Any] | None:
  """The state saved at `path` for the fit with `fingerprint`, or None: absent, or unusable
  (unreadable, or another fit's), which `read_cached` reports in one line and removes."""

  def read(found: Path) -> dict[str, Any]:
    payload = torch.load(found, map_location="cpu", weights_only=True)
    if payload["format"] != _FORMAT:
      raise ValueError("not a training snapshot")
    if payload["fingerprint"] != fingerprint:
      raise ValueError("a snapshot of another config, data or initialisation")
    return payload["state"]

  return read_cached(path, read, "training snapshot", "training that model from the start")


def discard(folder: str | os.PathLike[str]) -> None:
  """Removes a snapshot folder once the training it served is saved for good."""
  shutil.rmtree(folder, ignore_errors=True)
