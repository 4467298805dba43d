"""A motor-babbling dataset on disk: its layout, generating config, content hashes and checks.

Time convention (as in ``smpl.windows``): in an episode, action a_s is held for one control period
while the arm is at pose x_s and brings it to x_{s+1}; x_0 is the rest pose. An episode of L
samples therefore has L actions and L + 1 poses, and pose index s comes before action s.

Layout. A recording is E episodes, each starting from rest, of lengths as even as possible
(``episode_lengths``: 14,000 samples are 10 episodes of 1,400). Episodes are stored end to end,
whether or not their lengths are equal:

  actions          (S, action_dim) float64        a_0 .. a_{L-1} of episode 0, then episode 1, ...
  poses            (S + E, num_modules, 6) float64  x_0 .. x_L of episode 0, then episode 1, ...
  episode_lengths  (E,) int64

with S the number of samples. A pose is a module tip's position (m) then its unit orientation
vector (the tip frame's z-axis in world coordinates); modules are ordered from the base.
``Dataset.episode(e)`` gives one episode's poses and actions.

Files, under ``softbench_home() / "datasets" / key`` with key ``{robot}-n{S}-seed{seed}-{hash10}``
and hash10 the start of the sha256 of the generating config (robot name and MJCF, MuJoCo version,
samples, seed, episode lengths, control period, action stream, format version):

  dataset.npz   the arrays above, uncompressed, with deterministic bytes (``storage.npz_bytes``).
  dataset.json  the config and its sha256, the npz file's sha256, the arrays' sha256
                (``storage.arrays_sha256``), shapes and dtypes, and how the collection ran
                (softbench version, wall time, worker threads).

``dataset.json`` is written last: a folder without it holds no finished dataset.
"""

import dataclasses
import hashlib
import io
import json
import numbers
import pathlib

import mujoco
import numpy as np

from smpl.files import first_line  # An exception's message on one line; used package-wide.
import softbench
from softbench import robots
from softbench import storage
from softbench.data import seeding
from softbench.robots import recorder

FORMAT = "softbench-babbling-dataset"
FORMAT_VERSION = 1  # Bump whenever the arrays or the way they are generated change.
DEFAULT_SAMPLES = 14_000  # SPEC section 4: motor-babbling samples per robot configuration.
MAX_SHOWN_CHARS = 40  # Of a refused count, so that its refusal stays one short line.
MAX_SAMPLES = 10_000_000  # Most samples a dataset may have: 700 times the paper's, 3.2 GB of
# float64 poses and actions for tendon-5 (40 numbers a sample); more is a typo, not a dataset.
EPISODE_LENGTH = 1_400  # Samples per episode, at most; 14,000 samples make 10 episodes.
DATASETS_FOLDER = "datasets"
NPZ_NAME = "dataset.npz"
JSON_NAME = "dataset.json"
ACTION_DISTRIBUTION = "uniform in [-1, 1) per entry, held for one control period"
_HASH_LENGTH = 10  # Hex digits of the config hash in a dataset's folder name.
_DTYPES = {"actions": np.dtype("<f8"), "poses": np.dtype("<f8"), "episode_lengths": np.dtype("<i8")}


class DatasetError(ValueError):
  """A dataset file is missing, unreadable, corrupt, or not the one its config asks for."""


@dataclasses.dataclass(frozen=True, eq=False)
class Dataset:
  """A verified babbling dataset (layout in the module docstring); arrays are read-only.

  Attributes:
    path: The dataset's folder.
    config: The generating config, as hashed into the folder name.
    actions: (samples, action_dim) actions of all episodes, end to end.
    poses: (samples + episodes, num_modules, 6) poses of all episodes, end to end.
    episode_lengths: (episodes,) samples per episode.
    collection: How the collection ran: softbench version, wall time (s), worker threads.
  """

  path: pathlib.Path
  config: dict
  actions: np.ndarray
  poses: np.ndarray
  episode_lengths: np.ndarray
  collection: dict

  @property
  def robot_name(self) -> str:
    return self.config["robot"]

  @property
  def samples(self) -> int:
    return len(self.actions)

  @property
  def num_episodes(self) -> int:
    return len(self.episode_lengths)

  @property
  def num_modules(self) -> int:
    return self.poses.shape[1]

  @property
  def action_dim(self) -> int:
    return self.actions.shape[1]

  def describe(self) -> str:
    """One line: ``tendon-3: 14000 samples in 10 episodes (collection took 61.2 s)``."""
    seconds = self.collection.get("wall_time_s")
    took = "" if seconds is None else f" (collection took {seconds:.1f} s)"
    return f"{self.robot_name}: {self.samples} samples in {self.num_episodes} episodes{took}"

  def episode(self, index: int) -> tuple[np.ndarray, np.ndarray]:
    """Poses (L + 1, num_modules, 6) and actions (L, action_dim) of episode ``index``."""
    if not 0 <= index < self.num_episodes:
      raise IndexError(f"episode {index} out of range; the dataset has {self.num_episodes}")
    start = int(np.sum(self.episode_lengths[:index]))
    stop = start + int(self.episode_lengths[index])
    return self.poses[start + index : stop + index + 1], self.actions[start:stop]


def check_count(name: str, value: int, maximum: int | None = None) -> None:
  """Raises a one-line ValueError unless ``value`` is an integer of at least 1 and, where given,
  at most ``maximum`` (a count that work is sized by, checked before the work starts)."""
  shown = (
    repr(value) if len(repr(value)) <= MAX_SHOWN_CHARS else f"{repr(value)[:MAX_SHOWN_CHARS]}..."
  )
  if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
    raise ValueError(f"{name} must be a positive integer, got {shown}")
  if maximum is not None and value > maximum:
    raise ValueError(f"{name} must be at most {maximum:,}, got {shown}")


def read_npz(content: bytes, error_type: type[ValueError]) -> dict[str, np.ndarray]:
  """The arrays in the bytes of an .npz file; ``error_type`` (one line) if it is damaged."""
  try:
    with np.load(io.BytesIO(content), allow_pickle=False) as npz:
      return {name: npz[name] for name in npz.files}
  except Exception as error:
    # A damaged zip raises nearly anything: BadZipFile, ValueError, OSError, EOFError, KeyError,
    # NotImplementedError (a flipped "version needed" field), ...
    raise error_type(f"not a readable .npz: {first_line(error)}") from None


def episode_lengths(samples: int, episode_length: int = EPISODE_LENGTH) -> tuple[int, ...]:
  """Lengths of the fewest episodes of at most ``episode_length`` samples, as even as possible."""
  check_count("samples", samples)
  if samples > MAX_SAMPLES:  # Before the list of episodes, which would fill the memory.
    raise ValueError(f"samples must be at most {MAX_SAMPLES:,}, got {samples:,}")
  check_count("episode_length", episode_length)
  episodes = -(-samples // episode_length)
  base, longer = divmod(samples, episodes)
  return tuple(base + 1 if episode < longer else base for episode in range(episodes))


def resolve_robot(robot: str | robots.SoftArm) -> robots.SoftArm:
  """The arm of a registry name (``robots.make``'s ValueError if unknown), or ``robot`` itself."""
  if isinstance(robot, robots.SoftArm):
    return robot
  return robots.make(robot)


def generating_config(
  robot: str | robots.SoftArm,
  samples: int = DEFAULT_SAMPLES,
  seed: int = 0,
  episode_length: int = EPISODE_LENGTH,
) -> dict:
  """Everything the dataset's arrays depend on; raises a one-line ValueError on bad arguments."""
  arm = resolve_robot(robot)
  lengths = episode_lengths(samples, episode_length)
  seeding.check_seed(seed)
  return {
    "format_version": FORMAT_VERSION,
    "robot": arm.name,
    "robot_xml_sha256": arm.physics_sha256(),
    "mujoco_version": mujoco.__version__,
    "num_modules": arm.num_modules,
    "actuators_per_module": list(arm.actuators_per_module),
    "control_timestep": arm.control_timestep,
    "samples": int(samples),
    "seed": int(seed),
    "episode_lengths": list(lengths),
    "action_stream": seeding.BABBLING_STREAM,
    "action_distribution": ACTION_DISTRIBUTION,
  }


def config_sha256(config: dict) -> str:
  return hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()


def dataset_key(config: dict) -> str:
  """The folder name of the dataset of ``config``."""
  return (
    f"{config['robot']}-n{config['samples']}-seed{config['seed']}-"
    f"{config_sha256(config)[:_HASH_LENGTH]}"
  )


def dataset_folder(config: dict, home: str | pathlib.Path | None = None) -> pathlib.Path:
  """Where the dataset of ``config`` lives, under ``home`` (default ``softbench_home()``)."""
  home = pathlib.Path(home) if home is not None else storage.softbench_home()
  return home / DATASETS_FOLDER / dataset_key(config)


def expected_shapes(config: dict) -> dict[str, tuple[int, ...]]:
  lengths = config["episode_lengths"]
  samples, episodes = sum(lengths), len(lengths)
  return {
    "actions": (samples, sum(config["actuators_per_module"])),
    "poses": (samples + episodes, config["num_modules"], recorder.POSE_SIZE),
    "episode_lengths": (episodes,),
  }


def write(
  folder: pathlib.Path, config: dict, arrays: dict[str, np.ndarray], collection: dict
) -> None:
  """Writes ``dataset.npz`` then ``dataset.json`` atomically (layout in the module docstring)."""
  content = storage.npz_bytes(arrays)
  storage.write_cache_file(folder / NPZ_NAME, content, "dataset")
  manifest = {
    "format": FORMAT,
    "key": dataset_key(config),
    "config": config,
    "config_sha256": config_sha256(config),
    "npz_sha256": hashlib.sha256(content).hexdigest(),
    "arrays_sha256": storage.arrays_sha256(arrays),
    "arrays": {
      name: {"shape": list(array.shape), "dtype": array.dtype.str}
      for name, array in sorted(arrays.items())
    },
    "collection": {"softbench_version": softbench.__version__, **collection},
  }
  storage.write_cache_file(
    folder / JSON_NAME, json.dumps(manifest, indent=2, sort_keys=True) + "\n", "dataset's manifest"
  )


def read(folder: str | pathlib.Path, expected_config: dict | None = None) -> Dataset:
  """The verified dataset in ``folder``.

  Raises:
    DatasetError: a missing, unreadable, corrupt or edited file, or a dataset of another config
      than ``expected_config`` (one line naming the file).
  """
  folder = pathlib.Path(folder)
  manifest, shapes = _read_manifest(folder / JSON_NAME, expected_config)
  arrays = _read_arrays(folder / NPZ_NAME, manifest, shapes)
  for array in arrays.values():
    array.setflags(write=False)
  return Dataset(
    path=folder, config=manifest["config"], collection=manifest["collection"], **arrays
  )


def load(
  robot: str | robots.SoftArm,
  samples: int = DEFAULT_SAMPLES,
  seed: int = 0,
  home: str | pathlib.Path | None = None,
  episode_length: int = EPISODE_LENGTH,
) -> Dataset:
  """The verified babbling dataset of this config, collected before by ``collect``.

  Raises:
    ValueError: bad arguments (one line).
    DatasetError: the dataset was not collected, or its files fail a check.
  """
  config = generating_config(robot, samples, seed, episode_length)
  folder = dataset_folder(config, home)
  if not (folder / JSON_NAME).exists():
    raise DatasetError(
      f"{folder}: no dataset collected; run `softbench collect --robot "
      f"{config['robot']} --samples {samples} --seed {seed}`"
    )
  return read(folder, config)


def _read_manifest(
  path: pathlib.Path, expected_config: dict | None
) -> tuple[dict, dict[str, tuple[int, ...]]]:
  """The checked manifest and the array shapes its config implies."""

  def fail(problem: str) -> DatasetError:
    return DatasetError(f"{path}: {problem}")

  try:
    manifest = json.loads(path.read_text())
  except FileNotFoundError:
    raise fail("missing") from None
  except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
    raise fail(f"not readable JSON (truncated or corrupt): {first_line(error)}") from None
  if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
    raise fail("not a softbench babbling dataset manifest")
  for field, kind in (
    ("key", str),
    ("config", dict),
    ("config_sha256", str),
    ("npz_sha256", str),
    ("arrays_sha256", str),
    ("arrays", dict),
    ("collection", dict),
  ):
    if not isinstance(manifest.get(field), kind):
      raise fail(f"field {field!r} missing or not a {kind.__name__}")
  config = manifest["config"]
  if config.get("format_version") != FORMAT_VERSION:
    raise fail(
      f"format version {config.get('format_version')!r}; this softbench reads "
      f"version {FORMAT_VERSION}"
    )
  if config_sha256(config) != manifest["config_sha256"]:
    raise fail("config does not match its sha256 (edited or corrupt)")
  if manifest["key"] != dataset_key(config) or path.parent.name != manifest["key"]:
    raise fail(f"key {manifest['key']!r} does not match its config and folder {path.parent.name!r}")
  if expected_config is not None and config != expected_config:
    field = next(
      name
      for name in sorted(set(config) | set(expected_config))
      if config.get(name) != expected_config.get(name)
    )
    raise fail(
      f"generated with {field} = {config.get(field)!r}, expected {expected_config.get(field)!r}"
    )
  try:
    return manifest, expected_shapes(config)
  except (KeyError, TypeError) as error:
    raise fail(f"malformed config: {error!r}") from None


def _read_arrays(
  path: pathlib.Path, manifest: dict, shapes: dict[str, tuple[int, ...]]
) -> dict[str, np.ndarray]:
  def fail(problem: str) -> DatasetError:
    return DatasetError(f"{path}: {problem}")

  try:
    content = path.read_bytes()
  except FileNotFoundError:
    raise fail("missing") from None
  except OSError as error:
    raise fail(f"unreadable: {first_line(error)}") from None
  if hashlib.sha256(content).hexdigest() != manifest["npz_sha256"]:
    raise fail(f"sha256 differs from {JSON_NAME} (corrupt or truncated file)")
  try:
    arrays = read_npz(content, DatasetError)
  except DatasetError as error:
    raise fail(str(error)) from None
  if sorted(arrays) != sorted(_DTYPES):
    raise fail(f"holds arrays {sorted(arrays)}, expected {sorted(_DTYPES)}")
  for name, array in arrays.items():
    if array.dtype != _DTYPES[name] or array.shape != shapes[name]:
      raise fail(
        f"{name} is {array.dtype.str} {array.shape}, expected {_DTYPES[name].str} {shapes[name]}"
      )
  described = {
    name: {"shape": list(array.shape), "dtype": array.dtype.str} for name, array in arrays.items()
  }
  if manifest["arrays"] != described:
    raise fail(f"arrays do not match their description in {JSON_NAME}")
  if storage.arrays_sha256(arrays) != manifest["arrays_sha256"]:
    raise fail(f"arrays' sha256 differs from {JSON_NAME}")
  if arrays["episode_lengths"].tolist() != manifest["config"]["episode_lengths"]:
    raise fail("episode_lengths differ from the config")
  if not np.all(np.isfinite(arrays["poses"])) or np.any(np.abs(arrays["actions"]) > 1.0):
    raise fail("poses not finite or actions outside [-1, 1]")
  return arrays
