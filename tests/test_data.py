"""The babbling data layer: deterministic, resumable, verified datasets; splits; windows.

Collections are tiny (tens of samples, episodes of a few samples) so the whole file runs in
seconds; every test writes under its own temporary SOFTBENCH_HOME, never the real cache.
"""

import hashlib
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import torch

from smpl import windows as smpl_windows
from softbench import agents
from softbench import data
from softbench import robots
from softbench import storage
from softbench.data import chunks
from softbench.data import dataset
from softbench.robots import recorder

# Small but uneven: 4 episodes of 6, 6, 5 and 5 samples, saved in chunks of 2 control steps.
SMALL = {"robot": "tendon-2", "samples": 22, "seed": 3, "episode_length": 6}
CHUNK = 2
# Enough samples for windows of the default 15 steps in every split: 2 episodes of 100; the
# validation split (samples 140 to 160) and the test split lie in episode 1.
WINDOWED = {"robot": "tendon-2", "samples": 200, "seed": 0, "episode_length": 100}


@pytest.fixture(autouse=True)
def _temporary_home(tmp_path, monkeypatch):
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))


def collect(home=None, **overrides) -> data.Dataset:
  arguments = {**SMALL, "chunk_length": CHUNK, "workers": 2, "progress": False, **overrides}
  return data.collect(home=home, **arguments)


def npz_bytes(collected: data.Dataset) -> bytes:
  return (collected.path / dataset.NPZ_NAME).read_bytes()


def partial_folder(collected_config: dict) -> pathlib.Path:
  return dataset.dataset_folder(collected_config) / chunks.PARTIAL_FOLDER


def small_config() -> dict:
  return data.generating_config(
    SMALL["robot"], SMALL["samples"], SMALL["seed"], SMALL["episode_length"]
  )


@pytest.fixture(scope="module")
def reference_bytes(tmp_path_factory) -> bytes:
  """The npz bytes of SMALL collected in one go, on one thread, in one chunk."""
  home = tmp_path_factory.mktemp("reference")
  return npz_bytes(collect(home=home, workers=1, chunk_length=1000))


@pytest.fixture(scope="module")
def windowed(tmp_path_factory) -> data.Dataset:
  return data.collect(**WINDOWED, home=tmp_path_factory.mktemp("windowed"), progress=False)


def interrupt_after(monkeypatch, chunk_count: int) -> None:
  """Makes the next collection stop with KeyboardInterrupt once ``chunk_count`` chunks are
  saved, as Ctrl-C between two chunks would."""
  write = chunks.write
  written = []

  def write_then_interrupt(folder, chunk, collection):
    write(folder, chunk, collection)
    written.append(chunk)
    if len(written) == chunk_count:
      raise KeyboardInterrupt

  monkeypatch.setattr(chunks, "write", write_then_interrupt)


# 1. Layout and determinism.


def test_layout_and_time_convention():
  collected = collect()
  assert collected.episode_lengths.tolist() == [6, 6, 5, 5]
  assert collected.actions.shape == (22, 4) and collected.poses.shape == (26, 2, 6)
  arm = robots.make(SMALL["robot"])
  pose_recorder = recorder.PoseRecorder(arm)
  for episode in range(collected.num_episodes):
    poses, actions = collected.episode(episode)
    expected_actions = data.rng(SMALL["seed"], data.BABBLING_STREAM, episode).uniform(
      -1, 1, actions.shape
    )
    np.testing.assert_array_equal(actions, expected_actions)
    # Pose s before action s: the episode replayed alone from rest gives the same poses.
    expected_poses, _ = pose_recorder.record(actions[None])
    np.testing.assert_array_equal(poses, expected_poses[0])
  np.testing.assert_allclose(np.linalg.norm(collected.poses[..., 3:], axis=-1), 1.0)
  assert not collected.poses.flags.writeable
  manifest = json.loads((collected.path / dataset.JSON_NAME).read_text())
  assert manifest["collection"]["workers"] == 2
  assert manifest["collection"]["wall_time_s"] > 0
  assert collected.path.name.startswith("tendon-2-n22-seed3-")
  assert not (collected.path / chunks.PARTIAL_FOLDER).exists()


def test_same_seed_gives_same_bytes_whatever_the_workers_and_chunks(reference_bytes):
  assert npz_bytes(collect(workers=2, chunk_length=3)) == reference_bytes


def test_different_seeds_give_different_data():
  first, second = collect(seed=1), collect(seed=2)
  assert first.path != second.path
  assert not np.array_equal(first.actions, second.actions)
  assert not np.array_equal(first.poses[1:], second.poses[1:])


def test_config_hash_covers_the_physics():
  default = data.generating_config("tendon-2", 22, 3)
  longer = data.generating_config(robots.make("tendon-2", module_length=0.06), 22, 3)
  assert dataset.dataset_folder(default) != dataset.dataset_folder(longer)
  assert default["robot_xml_sha256"] != longer["robot_xml_sha256"]


def test_random_streams_are_independent_and_reproducible():
  draw = lambda *key: data.rng(*key).uniform(size=5)
  np.testing.assert_array_equal(draw(0, data.BABBLING_STREAM, 1), draw(0, data.BABBLING_STREAM, 1))
  assert not np.array_equal(
    draw(0, data.BABBLING_STREAM, 0), draw(0, data.HELD_OUT_BABBLING_STREAM, 0)
  )
  assert not np.array_equal(draw(0, data.BABBLING_STREAM, 0), draw(0, data.BABBLING_STREAM, 1))


@pytest.mark.parametrize("robot_name", robots.REGISTERED_ROBOTS)
def test_tiny_collection_of_every_robot(robot_name):
  collected = data.collect(robot_name, samples=6, episode_length=3, progress=False)
  arm = robots.make(robot_name)
  assert collected.actions.shape == (6, arm.action_dim)
  assert collected.poses.shape == (8, arm.num_modules, 6)
  rest = recorder.PoseRecorder(arm).poses(recorder.PoseRecorder(arm).rest_state())
  for episode in range(2):
    np.testing.assert_array_equal(collected.episode(episode)[0][0], rest)
  loaded = data.load(robot_name, samples=6, episode_length=3)
  np.testing.assert_array_equal(loaded.poses, collected.poses)


# 2. Resuming.


def test_interrupted_collection_resumes_to_identical_bytes(monkeypatch, reference_bytes):
  with monkeypatch.context() as patch:
    interrupt_after(patch, chunk_count=2)
    with pytest.raises(KeyboardInterrupt):
      collect()
  assert sorted(path.name for path in partial_folder(small_config()).iterdir()) == [
    "chunk-000000-000002.npz",
    "chunk-000002-000004.npz",
  ]
  resumed = collect()
  assert resumed.collection["resumed_from_step"] == 2 * CHUNK
  assert npz_bytes(resumed) == reference_bytes
  assert not partial_folder(small_config()).exists()


@pytest.mark.parametrize("damage", ["flip", "truncate"])
def test_corrupt_chunk_is_reported_and_recomputed(monkeypatch, reference_bytes, damage):
  with monkeypatch.context() as patch:
    interrupt_after(patch, chunk_count=3)
    with pytest.raises(KeyboardInterrupt):
      collect()
  second = partial_folder(small_config()) / "chunk-000002-000004.npz"
  content = bytearray(second.read_bytes())
  if damage == "flip":
    content[len(content) // 2] ^= 0xFF
  else:
    content = content[: len(content) // 2]
  second.write_bytes(bytes(content))
  with pytest.warns(storage.CorruptFileWarning, match="chunk-000002-000004.npz"):
    resumed = collect()
  assert resumed.collection["resumed_from_step"] == CHUNK
  assert npz_bytes(resumed) == reference_bytes


def test_a_chunk_of_another_collection_is_refused(monkeypatch, reference_bytes):
  # A valid chunk of the seed-4 collection, copied into the seed-3 collection's folder: its
  # poses would go with the wrong actions, so it is reported and recomputed.
  with monkeypatch.context() as patch:
    interrupt_after(patch, chunk_count=1)
    with pytest.raises(KeyboardInterrupt):
      collect(seed=4)
  foreign_config = data.generating_config(
    SMALL["robot"], SMALL["samples"], 4, SMALL["episode_length"]
  )
  (foreign,) = (dataset.dataset_folder(foreign_config) / chunks.PARTIAL_FOLDER).iterdir()
  partial_folder(small_config()).mkdir(parents=True)
  (partial_folder(small_config()) / foreign.name).write_bytes(foreign.read_bytes())
  with pytest.warns(storage.CorruptFileWarning, match="a chunk of another collection"):
    resumed = collect()
  assert resumed.collection["resumed_from_step"] == 0
  assert npz_bytes(resumed) == reference_bytes


@pytest.mark.parametrize("manifest", [True, False])
def test_a_folder_where_the_dataset_file_belongs_is_replaced(manifest, reference_bytes):
  # It once broke every collection until removed by hand.
  folder = dataset.dataset_folder(small_config())
  if manifest:
    collect()
  (folder / dataset.NPZ_NAME).unlink(missing_ok=True)
  (folder / dataset.NPZ_NAME / "stray").mkdir(parents=True)
  with pytest.warns(storage.CorruptFileWarning) as caught:
    collected = collect()
  assert len(caught) == 1 and str(folder / dataset.NPZ_NAME) in str(caught[0].message)
  assert npz_bytes(collected) == reference_bytes


def test_resuming_with_another_chunk_length_gives_identical_bytes(monkeypatch, reference_bytes):
  with monkeypatch.context() as patch:
    interrupt_after(patch, chunk_count=1)
    with pytest.raises(KeyboardInterrupt):
      collect(chunk_length=4)
  assert npz_bytes(collect(chunk_length=1, workers=1)) == reference_bytes


def test_complete_dataset_is_reused_without_simulating(monkeypatch):
  first = collect()

  def fail(*args, **kwargs):
    raise AssertionError("simulated again")

  monkeypatch.setattr(recorder.PoseRecorder, "record", fail)
  again = collect(workers=1, chunk_length=5)
  assert again.path == first.path
  np.testing.assert_array_equal(again.poses, first.poses)
  assert again.collection == first.collection


# 3. Integrity.


def _flip_npz(folder):
  path = folder / dataset.NPZ_NAME
  content = bytearray(path.read_bytes())
  content[len(content) // 2] ^= 0x01
  path.write_bytes(bytes(content))


def _truncate_npz(folder):
  path = folder / dataset.NPZ_NAME
  path.write_bytes(path.read_bytes()[:-100])


def _truncate_npz_and_rehash(folder):
  """A truncated npz whose manifest was updated to match: numpy's reader must fail cleanly."""
  _truncate_npz(folder)
  _edit_manifest(
    folder, npz_sha256=hashlib.sha256((folder / dataset.NPZ_NAME).read_bytes()).hexdigest()
  )


def _edit_manifest(folder, **fields):
  path = folder / dataset.JSON_NAME
  manifest = json.loads(path.read_text())
  manifest.update(fields)
  path.write_text(json.dumps(manifest))


def _edit_config(folder):
  manifest = json.loads((folder / dataset.JSON_NAME).read_text())
  _edit_manifest(folder, config={**manifest["config"], "seed": 4})


def _edit_arrays_hash(folder):
  _edit_manifest(folder, arrays_sha256="0" * 64)


def _truncate_json(folder):
  path = folder / dataset.JSON_NAME
  path.write_text(path.read_text()[:200])


def _remove_npz(folder):
  (folder / dataset.NPZ_NAME).unlink()


def _other_seed_manifest(folder):
  other = collect(seed=SMALL["seed"] + 1)
  for name in (dataset.JSON_NAME, dataset.NPZ_NAME):
    (folder / name).write_bytes((other.path / name).read_bytes())


DAMAGES = {
  "npz byte flip": (_flip_npz, dataset.NPZ_NAME),
  "truncated npz": (_truncate_npz, dataset.NPZ_NAME),
  "truncated npz, rehashed": (_truncate_npz_and_rehash, dataset.NPZ_NAME),
  "missing npz": (_remove_npz, dataset.NPZ_NAME),
  "edited config": (_edit_config, dataset.JSON_NAME),
  "edited arrays hash": (_edit_arrays_hash, dataset.NPZ_NAME),
  "truncated json": (_truncate_json, dataset.JSON_NAME),
  "files of another seed": (_other_seed_manifest, dataset.JSON_NAME),
}


@pytest.mark.parametrize("damage", DAMAGES)
def test_damaged_dataset_raises_one_line_dataset_error(damage):
  collected = collect()
  damage_files, named_file = DAMAGES[damage]
  damage_files(collected.path)
  with pytest.raises(data.DatasetError) as raised:
    data.load(
      SMALL["robot"], SMALL["samples"], SMALL["seed"], episode_length=SMALL["episode_length"]
    )
  message = str(raised.value)
  assert "\n" not in message and named_file in message, message


def test_collect_replaces_a_damaged_dataset(reference_bytes):
  _flip_npz(collect().path)
  with pytest.warns(storage.CorruptFileWarning, match=dataset.NPZ_NAME):
    assert npz_bytes(collect()) == reference_bytes


def test_load_of_an_uncollected_dataset_raises_dataset_error():
  with pytest.raises(data.DatasetError, match="no dataset collected"):
    data.load("tendon-1", samples=5)


@pytest.mark.parametrize(
  "arguments",
  [
    {"robot": "tendon-0"},
    {"robot": "octopus-8"},
    {"samples": 0},
    {"samples": 2.5},
    {"workers": 0},
    {"seed": -1},
    {"seed": 1.5},
    {"episode_length": 0},
    {"chunk_length": 0},
  ],
)
def test_bad_arguments_raise_one_line_value_error(arguments):
  with pytest.raises(ValueError) as raised:
    collect(**arguments)
  assert "\n" not in str(raised.value)
  assert not isinstance(raised.value, data.DatasetError)


def test_progress_bar_only_when_asked(capsys):
  collect(samples=4, progress=False)
  assert capsys.readouterr() == ("", "")
  collect(samples=5, progress=True)
  shown = capsys.readouterr()
  assert shown.out == "" and "5/5" in shown.err and "samples/s" in shown.err


# 4. Splits, normalisation, windows.


@pytest.mark.parametrize("lengths", [(1400,) * 10, (6, 6, 5, 5), (100, 100), (7,), (3, 50, 9)])
def test_split_pieces_are_contiguous_disjoint_and_70_10_20(lengths):
  pieces = data.split_pieces(lengths)
  flat = [(split, piece) for split in data.SPLITS for piece in pieces[split]]
  # In recording order, each piece starts where the one before stopped, or at a new episode.
  covered = [
    (piece.episode, sample) for _, piece in flat for sample in range(piece.start, piece.stop)
  ]
  assert covered == [
    (episode, sample) for episode, length in enumerate(lengths) for sample in range(length)
  ]
  total = sum(lengths)
  for split, fraction in zip(data.SPLITS, data.FRACTIONS):
    assert abs(sum(piece.samples for piece in pieces[split]) - fraction * total) <= 1
    assert len({piece.episode for piece in pieces[split]}) == len(pieces[split])
  if lengths == (1400,) * 10:
    assert [[piece.episode for piece in pieces[split]] for split in data.SPLITS] == [
      list(range(7)),
      [7],
      [8, 9],
    ]
    assert all(piece.samples == 1400 for _, piece in flat)


def test_normaliser_round_trip_and_constant_features():
  values = np.random.default_rng(0).normal(size=(50, 3)) * [1.0, 1e3, 0.0] + [0.0, 5.0, 7.0]
  normaliser = data.MinMaxNormaliser.fit(values)
  normalised = normaliser.normalise(values)
  assert np.all(np.isfinite(normalised))
  np.testing.assert_allclose(normalised[:, :2].min(axis=0), -1.0)
  np.testing.assert_allclose(normalised[:, :2].max(axis=0), 1.0)
  np.testing.assert_array_equal(normalised[:, 2], 0.0)  # Constant: centred, not scaled.
  np.testing.assert_allclose(normaliser.denormalise(normalised), values, rtol=1e-12, atol=1e-12)
  restored = data.MinMaxNormaliser.from_arrays(normaliser.to_arrays())
  np.testing.assert_array_equal(restored.normalise(values), normalised)
  empty = data.MinMaxNormaliser.fit(np.zeros((4, 0)))
  assert empty.normalise(np.zeros((2, 0))).shape == (2, 0)


def _views(arm):
  return [data.View.end_effector(arm), data.View.whole_arm(arm)] + [
    data.View.module(arm, module) for module in range(1, arm.num_modules + 1)
  ]


@pytest.mark.parametrize("robot_name", robots.REGISTERED_ROBOTS)
def test_view_sizes_for_every_robot(robot_name):
  arm = robots.make(robot_name)
  end_effector, whole_arm, *modules = _views(arm)
  assert (end_effector.pose_size, end_effector.action_size) == (6, arm.action_dim)
  assert (whole_arm.pose_size, whole_arm.action_size) == (6 * arm.num_modules, arm.action_dim)
  for module, view in enumerate(modules, start=1):
    assert view.pose_modules == (module - 1,)
    assert view.action_size == arm.actuators_per_module[module - 1]
    assert view.preceding_action_size == sum(arm.actuators_per_module[: module - 1])
    every = data.View.module_reading_every_actuation(arm, module)
    assert (every.pose_modules, every.action_indices) == (view.pose_modules, view.action_indices)
    assert sorted(every.preceding_action_indices + every.action_indices) == list(
      range(arm.action_dim)
    )
    assert every.name != view.name  # Their forward models are cached apart.
  with pytest.raises(ValueError):
    data.View.module(arm, arm.num_modules + 1)


@pytest.mark.parametrize("robot_name", robots.REGISTERED_ROBOTS)
def test_window_shapes_for_every_robot(robot_name):
  arm = robots.make(robot_name)
  collected = data.collect(robot_name, samples=20, episode_length=10, progress=False)
  for view in _views(arm):
    split = data.windows(collected, view, window_length=1)
    for windows in (split.train, split.validation, split.test):
      assert windows.poses.dtype == torch.float32
      assert windows.steps == 1
      assert (windows.pose_size, windows.action_size, windows.preceding_actions.shape[2]) == (
        view.pose_size,
        view.action_size,
        view.preceding_action_size,
      )


def _split_recordings(collected, view, split):
  pieces = data.split_pieces(collected.episode_lengths)[split]
  return [view.select(*piece.recording(collected)) for piece in pieces]


@pytest.mark.parametrize("module", [1, 2])
def test_windows_are_consecutive_rows_of_one_piece(windowed, module):
  view = data.View.module(robots.make(WINDOWED["robot"]), module)
  split_windows = data.windows(windowed, view)
  fitted = split_windows.normalisation
  steps = smpl_windows.SEQUENCE_LENGTH
  for split in data.SPLITS:
    windows = getattr(split_windows, split)
    recordings = _split_recordings(windowed, view, split)
    expected_count = sum(max(0, len(actions) - steps) for _, actions, _ in recordings)
    assert len(windows) == expected_count > 0
    for index in range(len(windows)):
      assert any(
        _window_in(windows, index, recording, fitted, steps) for recording in recordings
      ), (split, index)


def _window_in(windows, index, recording, fitted, steps) -> bool:
  poses, actions, preceding = (
    np.float32(normaliser.normalise(values))
    for normaliser, values in zip(
      (fitted.poses, fitted.actions, fitted.preceding_actions), recording
    )
  )
  window = [
    part[index].numpy() for part in (windows.poses, windows.actions, windows.preceding_actions)
  ]
  for start in range(len(actions) - steps):  # x_{-1} is poses[start].
    if (
      np.array_equal(window[0], poses[start : start + steps + 2])
      and np.array_equal(window[1], actions[start + 1 : start + steps + 1])
      and np.array_equal(window[2], preceding[start + 1 : start + steps + 1])
    ):
      return True
  return False


def test_normalisation_is_fitted_on_the_training_split_only(windowed):
  view = data.View.whole_arm(robots.make(WINDOWED["robot"]))
  split_windows = data.windows(windowed, view)
  fitted = split_windows.normalisation
  for part, normaliser in enumerate((fitted.poses, fitted.actions)):
    train = np.concatenate(
      [recording[part] for recording in _split_recordings(windowed, view, "train")]
    )
    np.testing.assert_array_equal(normaliser.minimum, train.min(axis=0))
    np.testing.assert_array_equal(normaliser.maximum, train.max(axis=0))
  assert split_windows.train.poses.abs().max() <= 1.0 + 1e-6
  assert split_windows.test.poses.abs().max() > 1.0  # Test poses outside the training range.
  arrays = fitted.to_arrays()
  assert sorted(arrays) == sorted(
    f"{field}_{stat}"
    for field in ("poses", "actions", "preceding_actions")
    for stat in ("minimum", "maximum")
  )
  restored = data.Normalisation.from_arrays(arrays)
  poses = windowed.poses.reshape(len(windowed.poses), -1)
  np.testing.assert_array_equal(restored.poses.normalise(poses), fitted.poses.normalise(poses))


def test_split_without_room_for_a_window_raises_value_error():
  with pytest.raises(ValueError, match=r"train split \(15 samples\) holds no window"):
    data.windows(collect(), data.View.end_effector(robots.make(SMALL["robot"])))


def test_atomic_writes_get_the_permissions_of_a_plain_open(tmp_path):
  plain, atomic = tmp_path / "plain.txt", tmp_path / "atomic.txt"
  plain.write_text("x")
  storage.write_atomically(atomic, "x")
  assert atomic.stat().st_mode == plain.stat().st_mode
  assert not list(tmp_path.glob("*.tmp"))


def test_every_cache_file_gets_the_permissions_of_a_plain_open(tmp_path, monkeypatch):
  # Checkpoints, forward models and training snapshots were 0600 while datasets were 0644, so a
  # colleague sharing a data home could not read them.
  monkeypatch.setenv(storage.HOME_VARIABLE, str(tmp_path / "home"))
  plain = tmp_path / "plain.txt"
  plain.write_text("x")
  agents.make("mlp", "tendon-1", 0, "tiny")
  files = [path for path in (tmp_path / "home").rglob("*") if path.is_file()]
  assert {"checkpoints", "forward", "datasets"} <= {
    path.relative_to(tmp_path / "home").parts[0] for path in files
  }
  assert {path.stat().st_mode for path in files} == {plain.stat().st_mode}


def test_a_full_disk_names_the_file_it_could_not_write(tmp_path, monkeypatch):
  monkeypatch.setattr(storage.os, "fsync", _full_disk)
  with pytest.raises(OSError) as caught:
    storage.write_atomically(tmp_path / "record.json", "{}")
  assert caught.value.filename == str(tmp_path / "record.json")
  assert caught.value.strerror == "No space left on device"


def _full_disk(descriptor):
  raise OSError(28, "No space left on device")


@pytest.mark.parametrize("failure", ["target is a folder", "full disk"])
def test_a_failed_atomic_write_leaves_no_temporary_file(failure, tmp_path, monkeypatch):
  target = tmp_path / "file.txt"
  if failure == "target is a folder":
    target.mkdir()
  else:
    target.write_text("old")
    monkeypatch.setattr(storage.os, "fsync", _full_disk)
  with pytest.raises(OSError):
    storage.write_atomically(target, "new")
  assert sorted(path.name for path in tmp_path.iterdir()) == ["file.txt"]
  assert failure == "target is a folder" or target.read_text() == "old"


WAIT_FOR_THE_LOCK = """
import sys
from softbench.data import babbling

def refuse(*args, **kwargs):
  raise AssertionError("collected although another process had")

babbling._collected = refuse
babbling.collect(**{config}, chunk_length={chunk}, workers=1, progress=False)
print("found it")
"""


def test_a_second_process_waits_for_the_collection_under_way_and_then_reads_it():
  """Two processes sharing a data home collect a dataset once: the second waits on the first's
  lock (one line), then finds the dataset made instead of collecting it again."""
  folder = dataset.dataset_folder(small_config())
  with storage.made_alone(folder, "babbling dataset"):
    second = subprocess.Popen(
      [sys.executable, "-c", WAIT_FOR_THE_LOCK.format(config=SMALL, chunk=CHUNK)],
      stdout=subprocess.PIPE,
      stderr=subprocess.PIPE,
      text=True,
    )
    waiting = second.stderr.readline()  # Blocks until the second process reaches the lock.
    assert waiting.startswith("softbench: waiting for another process making the babbling dataset")
    assert second.poll() is None
    collect(workers=1)  # Inside the held lock: it nests in this process.
  out, err = second.communicate(timeout=120)
  assert second.returncode == 0, err
  assert out.strip() == "found it"
