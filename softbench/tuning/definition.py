"""What a study is: its settings (``TuneSettings``), checked (``settings``), and the storage that
holds its trials (SQLite under the data home by default)."""

import dataclasses
import os

import optuna

from softbench import agents
from softbench import profiles
from softbench import robots
from softbench import storage
from softbench.agents import hyperparameters
from softbench.data import dataset
from softbench.learning import checkpoints

DEFAULT_TRIALS = 10  # Trials per study, the same for every agent (docs/tuning.md: budget).
MAX_TRIALS = 10_000  # Of a study: each trains a model; fewer than SEED_STRIDE keeps seeds apart.
DATABASE = "tuning.db"  # Default SQLite storage, under the data home.
MAX_STUDY_NAME_BYTES = 200  # A study name in UTF-8; its summary's file name adds ".json" (<= 255).
SEED_STRIDE = 100_000  # Trial n's sampler seed is seed * SEED_STRIDE + n (MAX_TRIALS fewer).


@dataclasses.dataclass(frozen=True)
class TuneSettings:
  """A study: which agent on which robot, its budget, data and storage."""

  agent: str
  robot: str
  trials: int
  profile: profiles.Profile
  storage: str
  study_name: str
  epochs: int
  """Epoch budget of a trial's inverse model (at most the profile's; forward models always get
  the profile's)."""
  seed: int = 0

  @property
  def trial_profile(self) -> profiles.Profile:
    """The profile a trial's inverse model trains under: the study's, with its epoch budget."""
    return dataclasses.replace(self.profile, max_epochs=self.epochs)

  @property
  def description(self) -> dict:
    """What the study's trials depend on; a study resumed under another description is refused."""
    arm = robots.make(self.robot)
    return {
      "agent": self.agent,
      "robot": self.robot,
      "robot_xml_sha256": arm.physics_sha256(),
      "profile": self.profile.name,
      "samples": self.profile.samples,
      "max_epochs": self.profile.max_epochs,
      "trial_epochs": self.epochs,
      "patience": self.profile.patience,
      "compile": self.profile.compile,
      "seed": self.seed,
      "search_space": hyperparameters.describe_space(self.agent),
      "training_version": checkpoints.TRAINING_VERSION,
    }


def default_storage() -> str:
  return f"sqlite:///{storage.softbench_home() / DATABASE}"


def settings(
  agent: str,
  robot: str,
  trials: int = DEFAULT_TRIALS,
  storage_url: str | None = None,
  profile: str = profiles.DEFAULT_PROFILE,
  study_name: str | None = None,
  epochs: int | None = None,
) -> TuneSettings:
  """Checked study settings; the storage is opened once to check that it can be.

  Raises:
    ValueError: an unknown or non-learning agent, an unknown robot or profile, trials outside
      1 .. ``MAX_TRIALS``, epochs outside 1 .. the profile's, a study name that is not a plain
      name (``check_study_name``) or a storage that cannot be opened (one line).
  """
  if agents.learner(agent) is None:
    raise ValueError(
      f"agent {agent!r} is not trained on babbling, so it has nothing to tune "
      f"here; choose one of {', '.join(agents.babbling_learners())}"
    )
  robots.make(robot)
  chosen_profile = profiles.get(profile)
  dataset.check_count("trials", trials, MAX_TRIALS)
  epochs = chosen_profile.max_epochs if epochs is None else epochs
  if (
    isinstance(epochs, bool)
    or not isinstance(epochs, int)
    or not 1 <= epochs <= chosen_profile.max_epochs
  ):
    raise ValueError(
      f"epochs must be a whole number from 1 to the {chosen_profile.name} "
      f"profile's {chosen_profile.max_epochs}, got {epochs!r}"
    )
  name = study_name if study_name is not None else f"{agent}-{robot}-{chosen_profile.name}"
  check_study_name(name)
  if storage_url is None:
    storage.softbench_home().mkdir(parents=True, exist_ok=True)
    storage_url = default_storage()
  open_storage(storage_url)
  return TuneSettings(agent, robot, trials, chosen_profile, storage_url, name, epochs)


def check_study_name(name: str) -> None:
  """Refuses a study name that is not a plain file name: its summary is ``NAME.json`` in the data
  home's ``SUMMARY_FOLDER``, and ``../../../tmp/x`` wrote outside the data home.

  Raises:
    ValueError: an empty name, one with a path separator or a control character, ``.`` or
      ``..``, or longer than ``MAX_STUDY_NAME_BYTES`` in UTF-8 (one line).
  """
  separators = {os.sep, os.altsep or os.sep}
  if not name.strip():
    raise ValueError("the study name must not be empty")
  if name in (".", "..") or any(character in separators for character in name):
    raise ValueError(f"the study name {name!r} must be a plain name, without '/' or '..'")
  if not name.isprintable():
    raise ValueError(f"the study name {name!r} must hold no control characters")
  if len(name.encode()) > MAX_STUDY_NAME_BYTES:
    raise ValueError(f"the study name must be at most {MAX_STUDY_NAME_BYTES} bytes long")


def open_storage(url: str) -> optuna.storages.RDBStorage:
  try:
    return optuna.storages.RDBStorage(url)
  except Exception as error:  # SQLAlchemy's URL, driver and connection errors, all bad input.
    lines = str(error).strip().splitlines()
    raise ValueError(
      f"cannot open the study storage {url!r}: {lines[0] if lines else type(error).__name__}"
    ) from None
