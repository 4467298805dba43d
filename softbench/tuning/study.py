"""Optuna studies that tune a learned agent's hyperparameters on validation data.

Every learned agent gets the same study: its search space (``agents.hyperparameters``), the same
number of trials, a seeded TPE sampler and a median pruner fed with per-epoch validation losses. A
trial trains the agent's inverse model with the sampled values in closed loop through frozen forward
models (trained once and shared, ``learning.forward_models``), on the profile's babbling dataset and
with the study's seed, as ``softbench run`` trains the agent's seed (for at most ``epochs`` epochs,
the profile's unless a study asks for fewer to afford more trials); its value is the best validation
loss: the action MSE over the whole arm on the validation split, in normalised units, the VAE's KL
term left out (``inverse_training.train_inverse``), the same quantity for every agent.

The first trial is the agent's values in use when the study starts (``hyperparameters.json``),
so each study measures the values it replaces on the same data. Studies live in an Optuna storage
(SQLite under the data home by default): re-running adds trials until the requested number have
finished (complete or pruned), and several machines can share one database. The sampler of trial
n is seeded with (seed, n), so an interrupted study continues as it would have.

A study with fewer epochs per trial than the profile's can confirm its choice (``confirm``): it
trains the previous and the best values again at the profile's full budget, as the agent will.
"""

import dataclasses
import datetime
import json
import math
import os
import pathlib

import optuna
from rich.progress import TextColumn

import softbench
from softbench import agents
from softbench import profiles
from softbench import progress as progress_bars
from softbench import robots
from softbench import storage
from softbench.agents import hyperparameters
from softbench.data import dataset
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training
from softbench.tuning import report

DEFAULT_TRIALS = 10  # Trials per study, the same for every agent (docs/tuning.md: budget).
MAX_TRIALS = 10_000  # Of a study: each trains a model; fewer than _SEED_STRIDE keeps seeds apart.
DATABASE = "tuning.db"  # Default SQLite storage, under the data home.
SUMMARY_FOLDER = "tuning"  # Study summaries, under the data home.
MAX_STUDY_NAME_BYTES = 200  # A study name in UTF-8; its summary's file name adds ".json" (<= 255).
_TPE_STARTUP_TRIALS = 4  # Trials sampled at random (the previous values among them) before TPE.
_PRUNER_STARTUP_TRIALS = 3  # Complete trials before the pruner may stop one.
_PRUNER_WARMUP_EPOCHS = 3  # Epochs every trial runs before it may be pruned.
_SEED_STRIDE = 100_000  # Trial n's sampler seed is seed * _SEED_STRIDE + n.
_FINISHED = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
OBJECTIVE = (
  "best validation action MSE of the closed-loop inverse model (normalised units, "
  "aux term left out) on the babbling dataset's validation split"
)


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
  _open_storage(storage_url)
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


def learner(agent: str) -> agents.Learner:
  """How ``agent`` (a learned agent of the registry) makes its inverse model."""
  return agents.learner(agent)


def run(settings: TuneSettings, show_progress: bool = True) -> dict:
  """Adds trials to the study until ``settings.trials`` have finished; returns its summary."""
  verbosity = optuna.logging.get_verbosity()
  optuna.logging.set_verbosity(optuna.logging.WARNING)  # The progress bar says what INFO would.
  try:
    return _run(settings, show_progress)
  finally:
    optuna.logging.set_verbosity(verbosity)


def _run(settings: TuneSettings, show_progress: bool) -> dict:
  study = _load_study(settings)
  trainer = _Trainer(settings, show_progress)

  def objective(trial: optuna.Trial) -> float:
    params = {name: space.suggest(trial, name) for name, space in trainer.space.items()}
    epochs = 0

    def on_epoch(step: int, loss: float) -> None:
      nonlocal epochs
      epochs += 1
      trial.set_user_attr("epochs", epochs)
      trial.report(loss, step)
      if trial.should_prune():
        raise optuna.TrialPruned(f"pruned at epoch {step}")

    return trainer.validation_loss(params, settings.trial_profile, on_epoch)

  with _TrialProgress(settings, study, show_progress) as progress:
    while _count(study, _FINISHED) < settings.trials:
      _enqueue_previous_values(study)
      study.sampler = _sampler(settings.seed, len(study.trials))
      study.optimize(objective, n_trials=1)
      progress.update(study)
  return summary(study, settings)


def confirm(settings: TuneSettings, study_summary: dict, show_progress: bool = True) -> dict:
  """The summary with ``full_budget``: the validation losses of the previous and the best values
  trained at the profile's full epoch budget (the trials' own values where that was theirs)."""
  previous, best = study_summary["previous_values"], study_summary["best"]
  if previous is None or best is None:
    raise ValueError(
      f"study {settings.study_name!r} has no complete trial of the previous "
      f"and the best values to confirm"
    )
  if settings.epochs == settings.profile.max_epochs:
    losses = {"previous": previous["value"], "best": best["value"]}
  else:
    trainer = _Trainer(settings, show_progress)
    losses = {"previous": _finite(trainer.validation_loss(previous["params"], settings.profile))}
    losses["best"] = (
      losses["previous"]
      if best["params"] == previous["params"]
      else _finite(trainer.validation_loss(best["params"], settings.profile))
    )
  return {**study_summary, "full_budget": {"epochs": settings.profile.max_epochs, **losses}}


class _Trainer:
  """Trains the study's agent with given values through the study's frozen forward models."""

  def __init__(self, settings: TuneSettings, show_progress: bool) -> None:
    self.settings = settings
    self.learner = learner(settings.agent)
    self.space = hyperparameters.search_space(settings.agent)
    arm = robots.make(settings.robot)
    self.views = self.learner.views(arm)
    self.windows, self.forwards = inverse_training.trained_forward_models(
      arm, self.views, settings.seed, settings.profile, show_progress
    )

  def validation_loss(
    self,
    params: dict,
    profile: profiles.Profile,
    on_epoch: inverse_training.EpochCallback | None = None,
  ) -> float:
    _, loss = inverse_training.train_inverse(
      self.views,
      self.windows,
      self.forwards,
      self.settings.seed,
      profile,
      self.learner.per_module,
      self.learner.make_model,
      params,
      on_epoch=on_epoch,
      restart_diverged=False,
    )
    return loss  # A diverging trial scores its own learning rate, not half of it.


def summary(study: optuna.Study, settings: TuneSettings) -> dict:
  """What the study found, without anything that depends on where it is stored."""
  complete = [trial for trial in study.trials if trial.state == optuna.trial.TrialState.COMPLETE]
  best = min(complete, key=lambda trial: trial.value) if complete else None
  previous = next(
    (
      trial
      for trial in study.trials
      if trial.user_attrs.get("previous_values") and trial.state == optuna.trial.TrialState.COMPLETE
    ),
    None,
  )
  describe = lambda trial: (
    None
    if trial is None
    else {"trial": trial.number, "value": _finite(trial.value), "params": trial.params}
  )
  return {
    "study": settings.study_name,
    "agent": settings.agent,
    "robot": settings.robot,
    "profile": settings.profile.name,
    "samples": settings.profile.samples,
    "max_epochs": settings.profile.max_epochs,
    "trial_epochs": settings.epochs,
    "patience": settings.profile.patience,
    "seed": settings.seed,
    "objective": OBJECTIVE,
    "search_space": hyperparameters.describe_space(settings.agent),
    "sampler": f"TPE, seed {settings.seed}, {_TPE_STARTUP_TRIALS} startup trials",
    "pruner": (
      f"median, after {_PRUNER_STARTUP_TRIALS} complete trials and "
      f"{_PRUNER_WARMUP_EPOCHS} warm-up epochs"
    ),
    "trials": {
      state: _count(study, (getattr(optuna.trial.TrialState, state.upper()),))
      for state in ("complete", "pruned", "fail")
    },
    "best": describe(best),
    "previous_values": describe(previous),
    "trial_seconds": round(sum(_seconds(trial) for trial in study.trials), 1),
    "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    "optuna_version": optuna.__version__,
    "softbench_version": softbench.__version__,
    "trial_table": [
      {
        "number": trial.number,
        "state": trial.state.name.lower(),
        "value": _finite(trial.value),
        "epochs": trial.user_attrs.get("epochs"),
        "seconds": round(_seconds(trial), 1),
        "params": trial.params,
      }
      for trial in study.trials
    ],
  }


def tune(
  settings: TuneSettings,
  confirm_budget: bool = False,
  summary_file: str | os.PathLike | None = None,
  adopt_best: bool = False,
) -> dict:
  """``softbench tune``: ``run``s the study (then ``confirm``s it if ``confirm_budget``), prints
  its report, writes its summary (to ``summary_file``, else ``summary_path``) and, if
  ``adopt_best``, ``adopt``s its best values; returns the summary. The summary's path is checked
  before the study runs (``storage.check_writable``: a folder there is refused at once, not once
  the trials are spent)."""
  path = storage.check_writable(summary_file or summary_path(settings), "the study summary")
  study_summary = run(settings)
  if confirm_budget:
    study_summary = confirm(settings, study_summary)
  print(report.summary_text(study_summary))
  write_summary(study_summary, path)
  print(f"study summary: {path}")
  if adopt_best:
    adopt(study_summary)
    print(f"adopted as {settings.agent}'s values on {settings.robot}: {hyperparameters.PATH}")
  return study_summary


def summary_path(settings: TuneSettings) -> pathlib.Path:
  return storage.softbench_home() / SUMMARY_FOLDER / f"{settings.study_name}.json"


def write_summary(study_summary: dict, path: pathlib.Path) -> None:
  storage.write_atomically(path, json.dumps(study_summary, indent=2, allow_nan=False) + "\n")


def adopt(study_summary: dict, path: pathlib.Path | None = None) -> None:
  """Commits the study's best values as the agent's values on its robot, with the summary
  (less its trial table)."""
  if study_summary["best"] is None:
    raise ValueError(f"study {study_summary['study']!r} has no complete trial to adopt")
  compact = {key: value for key, value in study_summary.items() if key != "trial_table"}
  hyperparameters.adopt(
    study_summary["agent"], study_summary["robot"], study_summary["best"]["params"], compact, path
  )


def _open_storage(url: str) -> optuna.storages.RDBStorage:
  try:
    return optuna.storages.RDBStorage(url)
  except Exception as error:  # SQLAlchemy's URL, driver and connection errors, all bad input.
    lines = str(error).strip().splitlines()
    raise ValueError(
      f"cannot open the study storage {url!r}: {lines[0] if lines else type(error).__name__}"
    ) from None


def _load_study(settings: TuneSettings) -> optuna.Study:
  study = optuna.create_study(
    storage=_open_storage(settings.storage),
    study_name=settings.study_name,
    direction="minimize",
    pruner=optuna.pruners.MedianPruner(
      n_startup_trials=_PRUNER_STARTUP_TRIALS, n_warmup_steps=_PRUNER_WARMUP_EPOCHS
    ),
    load_if_exists=True,
  )
  description = settings.description
  stored = study.user_attrs.get("settings")
  if stored is None:
    study.set_user_attr("settings", description)
    study.set_user_attr("previous_values", hyperparameters.values(settings.agent, settings.robot))
  elif stored != description:
    differences = ", ".join(
      key for key in sorted(description | stored) if stored.get(key) != description.get(key)
    )
    raise ValueError(
      f"study {settings.study_name!r} was made with other settings "
      f"({differences}); choose another --study name"
    )
  return study


def _enqueue_previous_values(study: optuna.Study) -> None:
  """Queues the values in use at the study's start, unless a trial has them or will."""
  waiting_or_done = (optuna.trial.TrialState.WAITING, *_FINISHED)
  if not any(
    trial.user_attrs.get("previous_values")
    for trial in study.trials
    if trial.state in waiting_or_done
  ):
    study.enqueue_trial(study.user_attrs["previous_values"], user_attrs={"previous_values": True})


def _sampler(seed: int, trial_number: int) -> optuna.samplers.TPESampler:
  return optuna.samplers.TPESampler(
    seed=seed * _SEED_STRIDE + trial_number, n_startup_trials=_TPE_STARTUP_TRIALS
  )


def _count(study: optuna.Study, states: tuple) -> int:
  return len(study.get_trials(deepcopy=False, states=states))


def _seconds(trial: optuna.trial.FrozenTrial) -> float:
  if trial.datetime_start is None or trial.datetime_complete is None:
    return 0.0
  return (trial.datetime_complete - trial.datetime_start).total_seconds()


def _finite(value: float | None) -> float | None:
  """``value``, or None where it is missing or not finite (JSON has no infinity)."""
  return value if value is not None and math.isfinite(value) else None


class _TrialProgress:
  """A progress bar over the study's finished trials, with the best value so far."""

  def __init__(self, settings: TuneSettings, study: optuna.Study, show: bool) -> None:
    self._progress = progress_bars.counting(show, extra=(TextColumn("{task.fields[best]}"),))
    self._task = self._progress.add_task(
      f"tune {settings.agent} {settings.robot}", total=settings.trials, best=""
    )
    self.update(study)

  def __enter__(self) -> "_TrialProgress":
    self._progress.start()
    return self

  def __exit__(self, *exception) -> None:
    self._progress.stop()

  def update(self, study: optuna.Study) -> None:
    complete = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    best = min((trial.value for trial in complete), default=None)
    self._progress.update(
      self._task,
      completed=_count(study, _FINISHED),
      best="" if best is None else f"best {best:.3e}",
    )
