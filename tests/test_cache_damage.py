"""Every cache of the data home follows one reading rule (``storage.read_cached``): whatever is
wrong with a cached file (truncated, a flipped bit, a zip whose flags ask for encryption, an
unknown compression method or a newer version, a folder in its place), it is reported in one
line naming the file, made again, and the result is what an undamaged cache gives."""

import dataclasses
import pathlib
from typing import Callable
import warnings

import numpy as np
import pytest

from softbench import agents
from softbench import data
from softbench import profiles
from softbench import robots
from softbench import storage
from softbench import suite
from softbench.data import babbling
from softbench.data import chunks
from softbench.data import dataset
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import checkpoints
from softbench.learning import forward_models
from softbench.learning import inverse as inverse_training
from softbench.runners import evaluation
from softbench.runners import run
from softbench.runners import run_settings
from softbench.suite import references

ROBOT = "tendon-1"


@dataclasses.dataclass(frozen=True)
class Cache:
  """A kind of cached file: ``use()`` makes it (or reads it back) and returns what it serves,
  as numpy arrays; ``path(home)`` is the file."""

  use: Callable[[], dict]
  path: Callable[[pathlib.Path], pathlib.Path]
  zip: bool = True  # An npz or torch file, whose zip header can be damaged.
  trained: bool = False  # Trained on ROBOT's tiny babbling dataset, which the home holds first.


def _dataset() -> dict:
  collected = babbling.collect(ROBOT, samples=12, seed=0, episode_length=6, progress=False)
  return {"poses": collected.poses, "actions": collected.actions}


def _reference() -> dict:
  made = references.reference(robots.make(ROBOT), "circle", length=4)
  return {"poses": made.poses, "actions": made.actions}


def _agent() -> dict:
  agent = agents.make("mlp", ROBOT, 0, "tiny")
  env = suite.load(ROBOT, "circle", seed=0, length=3)
  return {"actions": evaluation.run_episode(env, agent, "circle").actions}


def _forward() -> dict:
  arm = robots.make(ROBOT)
  _, (model,) = inverse_training.trained_forward_models(
    arm, [data.View.whole_arm(arm)], 0, profiles.get("tiny")
  )
  return {name: tensor.numpy() for name, tensor in model.state_dict().items()}


def _run_settings() -> run_settings.RunSettings:
  return run_settings.settings("circle", "zero", ROBOT, 1, "tiny")


def _episode() -> dict:
  settings = _run_settings()
  episode = episode_snapshots.load(settings, 0)
  if episode is None:
    episode = run.seed_episode(settings, 0)
    episode_snapshots.save(settings, 0, episode)
  return {"actions": episode.actions, "achieved": episode.achieved}


def _scores_path(home: pathlib.Path) -> pathlib.Path:
  return home / "runs" / "scores.json"


def _scores() -> dict:
  path = _scores_path(storage.softbench_home())
  scores = episode_snapshots.load_scores(path, "the test's episode")
  if scores is None:
    scores = {"position_mm": 1.5}
    episode_snapshots.save_scores(path, scores, "the test's episode")
  return {"position_mm": np.array(scores["position_mm"])}


LAYOUT = chunks.Layout(episodes=1, steps=4, num_modules=1, state_size=3, collection="test")
CHUNK = chunks.Chunk(0, 2, np.arange(12.0).reshape(1, 2, 1, 6), np.ones((1, 3)))


def _chunk_folder(home: pathlib.Path) -> pathlib.Path:
  return home / "datasets" / "test" / chunks.PARTIAL_FOLDER


def _chunk() -> dict:
  folder = _chunk_folder(storage.softbench_home())
  done = chunks.resume(folder, LAYOUT)
  if not done:
    chunks.write(folder, CHUNK, LAYOUT.collection)
    done = [CHUNK]
  return {"poses": done[0].poses, "states": done[0].final_states}


def _only(home: pathlib.Path, pattern: str) -> pathlib.Path:
  (path,) = home.glob(pattern)
  return path


CACHES = {
  "dataset": Cache(_dataset, lambda home: _only(home, f"datasets/*/{dataset.NPZ_NAME}")),
  "dataset manifest": Cache(
    _dataset, lambda home: _only(home, f"datasets/*/{dataset.JSON_NAME}"), zip=False
  ),
  "babbling chunk": Cache(_chunk, lambda home: _only(_chunk_folder(home), "chunk-*.npz")),
  "reference": Cache(_reference, lambda home: _only(home, "references/*.npz")),
  "reference description": Cache(
    _reference, lambda home: _only(home, "references/*.json"), zip=False
  ),
  "checkpoint": Cache(
    _agent, lambda home: _only(home, f"{checkpoints.CHECKPOINT_FOLDER}/*.pt"), trained=True
  ),
  "forward model": Cache(
    _forward, lambda home: _only(home, f"{forward_models.FOLDER}/*.pt"), trained=True
  ),
  "saved episode": Cache(_episode, lambda home: _only(home, "runs/*/seed0.npz")),
  "saved scores": Cache(_scores, _scores_path, zip=False),
}


def _zip_field(offset: int, value: bytes) -> Callable[[bytes], bytes]:
  """Sets a field of the first central-directory entry of a zip (npz, torch) file, which is
  where readers look for flags, compression and version."""

  def damage(content: bytes) -> bytes:
    at = content.index(b"PK\x01\x02") + offset
    return content[:at] + value + content[at + len(value) :]

  return damage


DAMAGES = {
  "truncated": lambda content: content[: len(content) // 2],
  "empty": lambda content: b"",
  "bit flipped": lambda content: (
    content[: len(content) // 2]
    + bytes([content[len(content) // 2] ^ 0x10])
    + content[len(content) // 2 + 1 :]
  ),
  "zip encrypted flag": _zip_field(8, b"\x01\x00"),
  "zip unknown compression": _zip_field(10, b"\x63\x00"),
  "zip version needed": _zip_field(6, b"\xff\x00"),
  "a folder in its place": None,
}
ZIP_DAMAGES = {name for name in DAMAGES if name.startswith("zip")}


@pytest.mark.parametrize(
  "kind,damage",
  [
    (kind, damage)
    for kind in CACHES
    for damage in DAMAGES
    if CACHES[kind].zip or damage not in ZIP_DAMAGES
  ],
)
def test_a_damaged_cache_file_is_reported_in_one_line_and_made_again(
  kind, damage, tmp_path, monkeypatch, babbled_home
):
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path))
  cache = CACHES[kind]
  if cache.trained:  # The dataset's own damage is the dataset kinds' subject.
    babbled_home(tmp_path, ROBOT)
  intact = cache.use()
  path = cache.path(tmp_path)
  content = path.read_bytes()
  assert content.startswith(b"PK") == cache.zip
  if DAMAGES[damage] is None:
    path.unlink()
    (path / "stray").mkdir(parents=True)
  else:
    path.write_bytes(DAMAGES[damage](content))
  with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    again = cache.use()
  reported = [
    str(entry.message) for entry in caught if entry.category is storage.CorruptFileWarning
  ]
  # A zip flag that the reader ignores (torch's reader and the version field) leaves the file
  # usable as it is; any other damage is reported.
  assert len(reported) == (0 if damage in ZIP_DAMAGES and not reported else 1)
  assert all(str(path) in message and "\n" not in message for message in reported)
  assert again.keys() == intact.keys()
  for name in intact:
    np.testing.assert_array_equal(again[name], intact[name])
  with warnings.catch_warnings():
    warnings.simplefilter("error")  # Made again intact: read back without a word.
    cache.use()
  assert path.is_file()
