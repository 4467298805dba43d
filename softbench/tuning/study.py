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

import datetime
import os

import optuna
from rich.progress import TextColumn

import softbench
from softbench import agents
from softbench import profiles
from softbench import progress as progress_bars
from softbench import robots
from softbench import storage
from softbench.agents import hyperparameters
from softbench.learning import inverse as inverse_training
from softbench.tuning import definition
from softbench.tuning import report
from softbench.tuning import summary_files

_TPE_STARTUP_TRIALS = 4  # Trials sampled at random (the previous values among them) before TPE.
_PRUNER_STARTUP_TRIALS = 3  # Complete trials before the pruner may stop one.
_PRUNER_WARMUP_EPOCHS = 3  # Epochs every trial runs before it may be pruned.
_FINISHED = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
OBJECTIVE = (
  "best validation action MSE of the closed-loop inverse model (normalised units, "
  "aux term left out) on the babbling dataset's validation split"
)


def learner(agent: str) -> agents.Learner:
  """How ``agent`` (a learned agent of the registry) makes its inverse model."""
  return agents.learner(agent)


def run(settings: definition.TuneSettings, show_progress: bool = True) -> dict:
  """Adds trials to the study until ``settings.trials`` have finished; returns its summary."""
  verbosity = optuna.logging.get_verbosity()
  optuna.logging.set_verbosity(optuna.logging.WARNING)  # The progress bar says what INFO would.
  try:
    return _run(settings, show_progress)
  finally:
    optuna.logging.set_verbosity(verbosity)


def _run(settings: definition.TuneSettings, show_progress: bool) -> dict:
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


def confirm(
  settings: definition.TuneSettings, study_summary: dict, show_progress: bool = True
) -> dict:
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
    losses = {
      "previous": summary_files.finite(
        trainer.validation_loss(previous["params"], settings.profile)
      )
    }
    losses["best"] = (
      losses["previous"]
      if best["params"] == previous["params"]
      else summary_files.finite(trainer.validation_loss(best["params"], settings.profile))
    )
  return {**study_summary, "full_budget": {"epochs": settings.profile.max_epochs, **losses}}


class _Trainer:
  """Trains the study's agent with given values through the study's frozen forward models."""

  def __init__(self, settings: definition.TuneSettings, show_progress: bool) -> None:
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


def summary(study: optuna.Study, settings: definition.TuneSettings) -> dict:
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
    else {"trial": trial.number, "value": summary_files.finite(trial.value), "params": trial.params}
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
    "trial_seconds": round(sum(summary_files.seconds(trial) for trial in study.trials), 1),
    "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    "optuna_version": optuna.__version__,
    "softbench_version": softbench.__version__,
    "trial_table": [
      {
        "number": trial.number,
        "state": trial.state.name.lower(),
        "value": summary_files.finite(trial.value),
        "epochs": trial.user_attrs.get("epochs"),
        "seconds": round(summary_files.seconds(trial), 1),
        "params": trial.params,
      }
      for trial in study.trials
    ],
  }


def tune(
  settings: definition.TuneSettings,
  confirm_budget: bool = False,
  summary_file: str | os.PathLike | None = None,
  adopt_best: bool = False,
) -> dict:
  """``softbench tune``: ``run``s the study (then ``confirm``s it if ``confirm_budget``), prints
  its report, writes its summary (to ``summary_file``, else ``summary_path``) and, if
  ``adopt_best``, ``adopt``s its best values; returns the summary. The summary's path is checked
  before the study runs (``storage.check_writable``: a folder there is refused at once, not once
  the trials are spent)."""
  path = storage.check_writable(
    summary_file or summary_files.summary_path(settings), "the study summary"
  )
  study_summary = run(settings)
  if confirm_budget:
    study_summary = confirm(settings, study_summary)
  print(report.summary_text(study_summary))
  summary_files.write_summary(study_summary, path)
  print(f"study summary: {path}")
  if adopt_best:
    summary_files.adopt(study_summary)
    print(f"adopted as {settings.agent}'s values on {settings.robot}: {hyperparameters.PATH}")
  return study_summary


def _load_study(settings: definition.TuneSettings) -> optuna.Study:
  study = optuna.create_study(
    storage=definition.open_storage(settings.storage),
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
    seed=seed * definition.SEED_STRIDE + trial_number, n_startup_trials=_TPE_STARTUP_TRIALS
  )


def _count(study: optuna.Study, states: tuple) -> int:
  return len(study.get_trials(deepcopy=False, states=states))


class _TrialProgress:
  """A progress bar over the study's finished trials, with the best value so far."""

  def __init__(self, settings: definition.TuneSettings, study: optuna.Study, show: bool) -> None:
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
