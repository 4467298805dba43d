"""The finished seeds of an interrupted ``softbench run``, so that the same command resumes.

A seed's episode (or, for Exp1S, the scores of the seed and of each of its episodes) is saved
atomically, with a content hash, as soon as it ends, under ``softbench_home()/runs/<name>-<key>/``.
The key hashes the run's settings (and a custom trajectory file's bytes), the source of
``softbench`` and ``smpl``, the MuJoCo and torch versions and the training device, so that a
changed setting or changed code never reuses a seed. The folder is removed once the run's record
is written, so a finished command run again evaluates afresh.
"""

import dataclasses
import functools
import hashlib
import json
import pathlib
import shutil
import sys
import warnings

import mujoco
import numpy as np
import torch

import smpl
from smpl import fitting
import softbench
from softbench import episodes
from softbench import storage
from softbench.data import dataset

FOLDER = "runs"
_ARRAYS = ("targets", "achieved", "poses", "actions", "rewards")
_SOURCE_SUFFIXES = (".py", ".json")


@functools.lru_cache(maxsize=None)
def source_sha256() -> str:
  """A hash of every source file of the ``softbench`` and ``smpl`` packages (names and bytes)."""
  digest = hashlib.sha256()
  for package in (softbench, smpl):
    root = pathlib.Path(package.__file__).parent
    for path in sorted(root.rglob("*")):
      if path.suffix in _SOURCE_SUFFIXES and "__pycache__" not in path.parts:
        digest.update(f"{package.__name__}/{path.relative_to(root).as_posix()}|".encode())
        digest.update(path.read_bytes())
  return digest.hexdigest()


def _device() -> str:
  """The device the run's agents train on (``smpl.fitting.default_device``)."""
  return str(fitting.default_device())


def keyed_folder(name: str, settings) -> pathlib.Path:
  """``softbench_home()/runs/<name>-<key>``, the key hashing ``settings`` (any value with a
  stable repr) with the source and library versions."""
  identity = repr((settings, source_sha256(), mujoco.__version__, torch.__version__, _device()))
  key = hashlib.sha256(identity.encode()).hexdigest()[:16]
  return storage.softbench_home() / FOLDER / f"{name}-{key}"


def folder(run) -> pathlib.Path:
  """Where the finished seeds of ``run`` (a ``runners.run_settings.RunSettings``) are kept."""
  trajectory = None  # A file edited under the same name differs; an unreadable one fails later,
  if run.trajectory:  # with its own error.
    try:
      trajectory = hashlib.sha256(pathlib.Path(run.trajectory).read_bytes()).hexdigest()
    except OSError:
      pass
  return keyed_folder(f"{run.agent}-{run.robot}-{run.task}", (dataclasses.asdict(run), trajectory))


def _path(run, seed: int) -> pathlib.Path:
  return folder(run) / f"seed{seed}.npz"


def report_resuming(path: pathlib.Path, seeds: int) -> None:
  """Says on stderr how many of ``seeds`` seeds an interrupted run left in ``path``, if any."""
  saved = len(list(path.glob("seed*")))
  if saved:
    print(
      f"resuming: {saved} of {seeds} seeds finished before the run was interrupted", file=sys.stderr
    )


def _keep(path: pathlib.Path, content: bytes | str, subject: str, what: str) -> None:
  """Writes the file of a finished ``subject`` (a seed, an episode); a failed write (a full disk,
  or an identical run elsewhere removing the folder as it ends) only warns: the run goes on, and
  an interrupted one would run ``subject`` again."""
  try:
    storage.write_atomically(path, content)
  except OSError as error:
    warnings.warn(
      f"could not keep the {what} of {subject} at {path} "
      f"({error.strerror or error}); the run goes on without it"
    )


def _owner(path: pathlib.Path) -> str:
  """What a saved file belongs to: its place in the data home (run key, seed, episode), stored
  in it and hashed with it, so that a file copied from another run or seed is refused."""
  return path.relative_to(storage.softbench_home()).as_posix()


def _check_owner(stored: str, path: pathlib.Path) -> None:
  if stored != _owner(path):
    raise ValueError(f"saved for {stored}, not for this run and seed")


def save(run, seed: int, episode: episodes.Episode) -> None:
  """Keeps ``seed``'s finished ``episode`` until the run ends (a failed write only warns)."""
  arrays = {name: np.asarray(getattr(episode, name)) for name in _ARRAYS}
  arrays["scored_modules"] = np.asarray(episode.scored_modules, dtype=int)
  arrays["owner"] = np.asarray(_owner(_path(run, seed)))
  arrays["sha256"] = np.asarray(storage.arrays_sha256(arrays))
  _keep(_path(run, seed), storage.npz_bytes(arrays), f"seed {seed}", "episode")


def load(run, seed: int) -> episodes.Episode | None:
  """``seed``'s episode saved by an interrupted run of the same settings and code, or None. An
  unreadable or altered file is deleted with a warning (``storage.read_cached``; the seed then
  runs again)."""

  def read(path: pathlib.Path) -> episodes.Episode:
    arrays = dataset.read_npz(path.read_bytes(), ValueError)
    expected = str(arrays.pop("sha256"))
    if expected != storage.arrays_sha256(arrays):
      raise ValueError("content hash mismatch")
    _check_owner(str(arrays.pop("owner")), path)
    return episodes.Episode(
      run.task, tuple(int(k) for k in arrays["scored_modules"]), *(arrays[name] for name in _ARRAYS)
    )

  return storage.read_cached(_path(run, seed), read, "saved episode", f"seed {seed} runs again")


def partial_path(run, seed: int) -> pathlib.Path:
  """Where the unfinished episode of ``seed`` is kept while it runs (``save_partial``)."""
  return folder(run) / f"unfinished-seed{seed}.npz"


_AGENT_PREFIX = "agent_"  # Before the names of the agent's episode state in an unfinished episode.


def save_partial(path: pathlib.Path, actions: list[np.ndarray], agent_state: dict) -> None:
  """Keeps an unfinished episode at ``path``: the actions taken so far and the agent's episode
  state after them (``Agent.episode_state``); a failed write only warns."""
  arrays = {f"{_AGENT_PREFIX}{name}": np.asarray(value) for name, value in agent_state.items()}
  arrays["actions"] = np.asarray(actions, dtype=float).reshape(len(actions), -1)
  arrays["owner"] = np.asarray(_owner(path))
  arrays["sha256"] = np.asarray(storage.arrays_sha256(arrays))
  _keep(path, storage.npz_bytes(arrays), f"an unfinished episode ({len(actions)} steps)", "state")


def load_partial(path: pathlib.Path) -> tuple[np.ndarray, dict] | None:
  """The actions and agent state an interrupted episode kept at ``path`` (``save_partial``), or
  None; an unreadable or altered file is deleted with a warning (the episode then starts again)."""

  def read(found: pathlib.Path) -> tuple[np.ndarray, dict]:
    arrays = dataset.read_npz(found.read_bytes(), ValueError)
    if str(arrays.pop("sha256")) != storage.arrays_sha256(arrays):
      raise ValueError("content hash mismatch")
    _check_owner(str(arrays.pop("owner")), found)
    state = {
      name.removeprefix(_AGENT_PREFIX): value
      for name, value in arrays.items()
      if name.startswith(_AGENT_PREFIX)
    }
    return arrays["actions"], state

  return storage.read_cached(path, read, "unfinished episode", "the episode starts again")


def _scores_sha256(scores: dict) -> str:
  return hashlib.sha256(json.dumps(scores, sort_keys=True).encode()).hexdigest()


def save_scores(path: pathlib.Path, scores: dict, subject: str) -> None:
  """Keeps the finished ``scores`` (JSON-serialisable) of ``subject`` (a seed, an episode) at
  ``path`` until the run ends (a failed write only warns)."""
  owned = {"scores": scores, "owner": _owner(path)}
  text = json.dumps({**owned, "sha256": _scores_sha256(owned)})
  _keep(path, text, subject, "scores")


def load_scores(path: pathlib.Path, subject: str) -> dict | None:
  """The scores of ``subject`` that an interrupted run saved at ``path``, or None; an unreadable
  or altered file is deleted with a warning (``storage.read_cached``; ``subject`` then runs
  again)."""

  def read(found: pathlib.Path) -> dict:
    saved = json.loads(found.read_text())
    owned = {"scores": saved["scores"], "owner": saved["owner"]}
    if saved["sha256"] != _scores_sha256(owned):
      raise ValueError("content hash mismatch")
    _check_owner(saved["owner"], found)
    return saved["scores"]

  return storage.read_cached(path, read, "saved scores", f"{subject} runs again")


def discard(run) -> None:
  """Removes the finished seeds of ``run`` once its record no longer needs them."""
  discard_folder(folder(run))


def discard_folder(path: pathlib.Path) -> None:
  """Removes a folder of finished seeds (``keyed_folder``) once the record no longer needs it."""
  shutil.rmtree(path, ignore_errors=True)
