"""Exp1S in physics: SMPL learns tendon-1 .. tendon-5 in sequence, one column per configuration,
and every configuration is scored on its end effector, closed and open loop, in MuJoCo. The
configurations are arms of one tendon family (``tendon`` by default; ``tendon-local`` is the
paper's module-local plant): ``family-1`` .. ``family-5``.

Training (cached per seed, like the agents' checkpoints): configuration N's babbling dataset (data
seed 0, the profile's sample count) in the end-effector view, a frozen forward model, then a new
column trained in closed loop with the earlier ones frozen (``smpl.protocol.train_next_column``).
After every stage, every column so far is scored on its own test windows (pose MSE through its
forward model): the model-level forgetting matrix, measured as training goes.

Acting: configuration N is driven by column N alone, reading the earlier columns through its
laterals (``ProgressiveColumn``), exactly as if modules N+1.. were detached. Column c reads only
columns 0..c, so its actions after stage s >= c are those after stage c; the physics forgetting
matrix (normalised tip error on spiral) is therefore filled from one episode per configuration
once the model-level matrix shows every earlier column's score unchanged, to the last bit, after
every later stage. A changed score would be forgetting, and raises.
"""

from collections.abc import Sequence
import dataclasses
import pathlib
import sys
import time

import numpy as np

from smpl import fitting
from smpl import progressive
from softbench import data
from softbench import episodes
from softbench import metrics
from softbench import profiles
from softbench import suite
from softbench import zoo
from softbench.agents import hyperparameters
from softbench.agents import learned
from softbench.data import dataset
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import exp1s as exp1s_training
from softbench.learning import inverse as inverse_training
from softbench.records import exp1s as exp1s_records
from softbench.records import provenance
from softbench.records.exp1s import DEFAULT_FAMILY
from softbench.records.exp1s import FORGETTING_TASK
from softbench.records.exp1s import FORMAT as RECORD_FORMAT
from softbench.records.exp1s import LOOPS
from softbench.records.exp1s import METRICS
from softbench.records.exp1s import PROTOCOL
from softbench.records.exp1s import TASKS
from softbench.records.exp1s import VERSION as RECORD_VERSION
from softbench.runners import evaluation
from softbench.runners import parallel_seeds


@dataclasses.dataclass(frozen=True)
class Exp1sSettings:
  """A checked Exp1S run (``softbench run --protocol exp1s``)."""

  profile: profiles.Profile
  family: str
  seeds: int | None = None  # None: the profile's.


def settings(
  protocol_name: str,
  agent: str,
  profile: str = profiles.DEFAULT_PROFILE,
  family: str | None = None,
  seeds: int | None = None,
  eval_mode: str = "physics",
  task_options: Sequence[str] = (),
) -> Exp1sSettings:
  """Checked settings of ``softbench run --protocol``, its seeds resolved (None: the profile's):
  Exp1S fixes its robots, tasks and loops, so it takes agent smpl, the physics eval mode and none
  of a task run's options (``task_options``: the flags given, e.g. ``--task``).

  Raises:
    ValueError: another protocol or agent, a task run's option, another eval mode, an unknown
      profile or family, fewer than one seed (one line).
  """
  if protocol_name != PROTOCOL:
    raise ValueError(
      f"unknown protocol {protocol_name!r}; choose {PROTOCOL} (SMPL's Exp1S table) or "
      f"continual (--stream STREAM --agent STRATEGY); exp2s and exp2r are the tasks on "
      f"tendon-3 and pneumatic-433: softbench run --task TASK --agent AGENT"
    )
  if agent != "smpl":
    raise ValueError(
      f"--protocol {PROTOCOL} trains SMPL's columns in sequence; it takes --agent smpl, "
      f"got {agent!r}"
    )
  check_fixed_options(PROTOCOL, "its robots, tasks and loops", task_options, eval_mode)
  chosen = profiles.get(profile)
  family = family or DEFAULT_FAMILY
  exp1s_training.protocol(family)
  return Exp1sSettings(chosen, family, seed_count(chosen, seeds))


def check_fixed_options(
  protocol_name: str, fixed: str, task_options: Sequence[str], eval_mode: str
) -> None:
  """Refuses a task run's options (``task_options``: the flags given) and any eval mode but
  physics for a protocol that fixes ``fixed`` (one line)."""
  if task_options or eval_mode != "physics":
    raise ValueError(
      f"--protocol {protocol_name} fixes {fixed}; drop {', '.join(task_options) or '--eval'}"
    )


def seed_count(profile: profiles.Profile, seeds: int | None) -> int:
  """``seeds``, or the profile's if None.

  Raises:
    ValueError: fewer than one seed or more than ``profiles.MAX_SEEDS`` (one line).
  """
  seeds = profile.seeds if seeds is None else seeds
  dataset.check_count("seeds", seeds, profiles.MAX_SEEDS)
  return seeds


@dataclasses.dataclass(frozen=True, eq=False)
class Exp1sModel:
  """The trained network, each configuration's controller, and the model-level forgetting
  matrices (stages x configurations, NaN above the diagonal)."""

  network: progressive.ProgressiveLSTM
  controllers: list[learned.Controller]
  arms: list
  forgetting_pose_mse: np.ndarray
  forgetting_action_mse: np.ndarray

  def agent(
    self, configuration: int, seed: int, acting: learned.Acting = learned.Acting()
  ) -> learned.LearnedAgent:
    """The controller of configuration ``configuration`` (1 = the one-module arm): its column
    alone, acting as ``acting``."""
    index = configuration - 1
    column = progressive.ProgressiveColumn(self.network, index)
    return learned.LearnedAgent(self.arms[index], seed, column, [self.controllers[index]], acting)


def _params(family: str) -> dict:
  """SMPL's hyperparameters for ``family``'s sequence, by its last robot (the agent's, tuned on
  tendon-3 unless that robot has its own; the columns keep the SPEC's size)."""
  return hyperparameters.values("smpl", exp1s_training.protocol(family).robot_names[-1])


def checkpoint_path(
  seed: int, profile: profiles.Profile, family: str = DEFAULT_FAMILY
) -> pathlib.Path:
  """Where ``build`` caches the Exp1S network of ``seed`` (it exists once trained)."""
  return exp1s_training.checkpoint_path(seed, profile, _params(family), family)


def build(
  seed: int, profile: profiles.Profile, show_progress: bool = False, family: str = DEFAULT_FAMILY
) -> Exp1sModel:
  """The Exp1S network of ``seed`` and its controllers: from the checkpoint cache, or trained now
  and cached (``learning.exp1s``)."""
  models, arms, views = exp1s_training.load_or_train(
    seed, profile, _params(family), show_progress, family
  )
  return Exp1sModel(
    models.inverse,
    learned.controllers(views, models.forwards, models.normalisations),
    arms,
    models.arrays["forgetting/pose_mse"],
    models.arrays["forgetting/action_mse"],
  )


class ForgettingDetected(RuntimeError):
  """A frozen column's score changed after a later stage (a defect of softbench, not of the
  input)."""


def check_no_forgetting(matrix: np.ndarray) -> None:
  """Raises ForgettingDetected if any configuration's score changed after a later stage (to the
  last bit)."""
  for stage in range(1, len(matrix)):
    for configuration in range(stage):
      if matrix[stage, configuration] != matrix[configuration, configuration]:
        raise ForgettingDetected(
          f"configuration {configuration + 1} changed after stage {stage + 1}: "
          f"{float(matrix[configuration, configuration])!r} -> "
          f"{float(matrix[stage, configuration])!r}, "
          f"though its column is frozen (a defect of softbench; please report it)"
        )


def end_effector_scores(episode: episodes.Episode, length: float) -> dict:
  """The end effector's errors of ``episode`` (each metric measured, mean over its steps)."""
  score = episode.score(length)
  return {name: getattr(score, name)[-1].mean for name in METRICS if getattr(score, name)}


def finished_seeds_folder(profile: profiles.Profile, family: str = DEFAULT_FAMILY) -> pathlib.Path:
  """Where the scores of the seeds (and, under ``EPISODES_FOLDER``, of the episodes) that an
  interrupted run finished are kept (``episodes.snapshots``: keyed by the settings and the code)."""
  return episode_snapshots.keyed_folder(
    f"smpl-{PROTOCOL}", (dataclasses.asdict(profile), exp1s_training.protocol(family).robot_names)
  )


EPISODES_FOLDER = "episodes"  # Inside finished_seeds_folder: the finished episodes of a seed.


def run_seed(
  seed: int, profile: profiles.Profile, family: str = DEFAULT_FAMILY, show_progress: bool = False
) -> dict:
  """``score_seed``, or the scores an interrupted run of the same settings and code kept: the
  seed's, or those of each episode it had finished."""
  folder = finished_seeds_folder(profile, family)
  scores = kept_scores(Exp1sSettings(profile, family), seed)
  if scores is None:
    episodes = folder / EPISODES_FOLDER
    kept = len(list(episodes.glob(f"seed{seed}-*.json")))
    if kept and show_progress:
      total = len(exp1s_training.protocol(family).robot_names) * len(LOOPS) * len(TASKS)
      print(
        f"resuming seed {seed}: {kept} of its {total} episodes finished before the run was "
        "interrupted",
        file=sys.stderr,
      )
    scores = score_seed(seed, profile, show_progress, episodes, family)
    keep_scores(Exp1sSettings(profile, family), seed, scores)
  return scores


def _kept_seed_file(run: Exp1sSettings, seed: int) -> tuple[pathlib.Path, str]:
  return finished_seeds_folder(run.profile, run.family) / f"seed{seed}.json", f"seed {seed}"


def kept_scores(run: Exp1sSettings, seed: int) -> dict | None:
  """The scores of ``seed`` that an interrupted run of ``run``'s settings and code kept; None
  if there are none (or they are damaged: reported on one line)."""
  return episode_snapshots.load_scores(*_kept_seed_file(run, seed))


def keep_scores(run: Exp1sSettings, seed: int, scores: dict) -> None:
  """Keeps the scores of ``seed`` until the record of ``run`` is written (``finish``)."""
  path, subject = _kept_seed_file(run, seed)
  episode_snapshots.save_scores(path, scores, subject)


def score_seed(
  seed: int,
  profile: profiles.Profile,
  show_progress: bool,
  kept_episodes: pathlib.Path,
  family: str = DEFAULT_FAMILY,
) -> dict:
  """Trains (or loads) seed ``seed``'s network and scores every configuration, task and loop.

  Each episode's scores are kept in ``kept_episodes`` as it ends, and an episode whose scores
  are there already is not run again (they do not depend on the order: every episode
  starts from a reset agent and a fresh environment).

  Returns {"seed", "scores": {loop: {task: [per configuration {metric: value}]}},
  "forgetting_model_pose_mse", "forgetting_tip_percent"} (matrices as nested lists, NaN -> None).
  """
  model = build(seed, profile, show_progress, family)
  check_no_forgetting(model.forgetting_pose_mse)
  check_no_forgetting(model.forgetting_action_mse)
  scores = {loop: {task: [] for task in TASKS} for loop in LOOPS}
  for configuration, arm in enumerate(model.arms, start=1):
    for loop, error_source in LOOPS.items():
      agent = model.agent(configuration, seed, learned.Acting(error_source))
      for task in TASKS:
        name = f"seed{seed}-configuration{configuration}-{loop}-{task}"
        subject = f"seed {seed}'s {loop}-loop {task} episode of configuration {configuration}"
        path = kept_episodes / f"{name}.json"
        entry = episode_snapshots.load_scores(path, subject)
        if entry is None:
          env = suite.load(
            arm, task, seed=seed, **suite.length_options(task, profile.episode_length)
          )
          episode = evaluation.run_episode(env, agent, task, show_progress)
          entry = end_effector_scores(episode, arm.length)
          episode_snapshots.save_scores(path, entry, subject)
        scores[loop][task].append(entry)
  tip = [entry["normalised_tip_percent"] for entry in scores["closed"][FORGETTING_TASK]]
  stages = len(model.arms)
  physics = [[tip[c] if c <= s else None for c in range(stages)] for s in range(stages)]
  model_level = [
    [None if np.isnan(value) else float(value) for value in row]
    for row in model.forgetting_pose_mse
  ]
  return {
    "seed": seed,
    "scores": scores,
    "forgetting_model_pose_mse": model_level,
    "forgetting_tip_percent": physics,
  }


def execute(
  profile: profiles.Profile,
  seeds: int | None = None,
  show_progress: bool = True,
  workers: int | None = None,
  keep_seeds: bool = False,
  family: str = DEFAULT_FAMILY,
) -> dict:
  """Every seed (in parallel processes), then the result record with full provenance.

  Each finished seed's scores are kept until the end, so that an interrupted run resumes with
  the seeds still to run; unless ``keep_seeds``, they are discarded at the end (else the caller
  discards them, ``episode_snapshots.discard_folder(finished_seeds_folder(profile, family))``,
  once the record is safely written)."""
  started = time.perf_counter()
  origin = provenance.provenance(str(fitting.default_device()))
  seeds = seed_count(profile, seeds)
  sequence = exp1s_training.protocol(family)
  taken, trained = zoo.take([checkpoint_path(seed, profile, family) for seed in range(seeds)])
  for arm, _ in [] if trained else sequence.column_views():  # Every core, before the seeds.
    data.collect(
      arm, samples=profile.samples, seed=inverse_training.DATA_SEED, progress=show_progress
    )
  if show_progress:
    episode_snapshots.report_resuming(finished_seeds_folder(profile, family), seeds)
  per_seed = parallel_seeds.over_seeds(
    run_seed, seeds, (profile, family), f"smpl {PROTOCOL}", show_progress, workers
  )
  if not keep_seeds:
    episode_snapshots.discard_folder(finished_seeds_folder(profile, family))
  return assemble_record(
    Exp1sSettings(profile, family, seeds), origin, per_seed, taken, time.perf_counter() - started
  )


def assemble_record(
  run: Exp1sSettings, origin: dict, per_seed: list[dict], taken: list[str], wall_time_s: float
) -> dict:
  """The Exp1S record of ``run`` (its ``seeds`` given): provenance ``origin``
  (``records.provenance``), every seed's scores (``score_seed``, seed order), the zoo files
  ``taken`` for its networks, the sha256 of each seed's network (``zoo.weights_section``) and
  ``wall_time_s``."""
  return {
    "format": RECORD_FORMAT,
    "version": RECORD_VERSION,
    **origin,
    "protocol": PROTOCOL,
    "agent": "smpl",
    "robots": list(exp1s_training.protocol(run.family).robot_names),
    "tasks": list(TASKS),
    "profile": run.profile.name,
    "profile_settings": dataclasses.asdict(run.profile),
    "seeds": run.seeds,
    "per_seed": per_seed,
    **zoo.section(taken),
    **zoo.weights_section(
      [[checkpoint_path(seed, run.profile, run.family)] for seed in range(run.seeds)]
    ),
    "wall_time_s": round(wall_time_s, 3),
  }


def _statistic(values: list[float]) -> str:
  statistic = metrics.Statistic.of(values)
  return f"{statistic.mean:.2f} ± {statistic.std:.2f}"


def table(record: dict) -> str:
  """The paper's Exp1S layout: per loop, configurations by rows, per task position (mm) and
  orientation (deg) of the end effector; then normalised tip error; then the forgetting matrix."""
  per_seed, configurations = record["per_seed"], len(record["robots"])
  lines = [
    f"smpl {record['protocol']} ({', '.join(record['robots'])}), profile "
    f"{record['profile']}, {record['seeds']} seed(s), end effector in physics: "
    f"mean ± std over seeds"
  ]
  for metric, label in (
    ("position_mm", "position (mm) / orientation (deg)"),
    ("normalised_tip_percent", "normalised tip error (%)"),
  ):
    for loop in LOOPS:
      lines += [
        "",
        f"{loop} loop, {label}",
        f"{'config':<8}" + "".join(f"{task:>22}" for task in record["tasks"]),
      ]
      for index in range(configurations):
        cells = []
        for task in record["tasks"]:
          value = lambda name: [seed["scores"][loop][task][index][name] for seed in per_seed]
          cell = _statistic(value(metric))
          if metric == "position_mm":
            cell += f" / {metrics.Statistic.of(value('orientation_deg')).mean:.1f}"
          cells.append(f"{cell:>22}")
        lines.append(f"{index + 1:<8}" + "".join(cells))
  lines += [
    "",
    f"forgetting matrix: normalised tip error (%) on {FORGETTING_TASK}, closed loop, "
    f"of each configuration (columns) after each stage (rows)",
    f"{'stage':<8}" + "".join(f"{c + 1:>16}" for c in range(configurations)),
  ]
  for stage in range(configurations):
    cells = [
      _statistic([seed["forgetting_tip_percent"][stage][c] for seed in per_seed])
      if c <= stage
      else ""
      for c in range(configurations)
    ]
    lines.append(f"{stage + 1:<8}" + "".join(f"{cell:>16}" for cell in cells))
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)


def finish(record: dict, files: list[pathlib.Path]) -> None:
  """What follows a saved record (``files``, the results folder's first): the finished seeds
  kept for resuming go (only now: a failed write leaves a run that resumes), then the heat map
  of forgetting beside the record."""
  from softbench import plots  # Not at the top: as in run.finish, no seed worker needs it.

  profile, family = profiles.get(record["profile"]), exp1s_records.family(record)
  episode_snapshots.discard_folder(finished_seeds_folder(profile, family))
  path = files[0]
  heat_map_path = path.with_name(f"{path.stem}-forgetting.png")
  matrix = exp1s_records.mean_forgetting(record)
  heat_map = plots.forgetting_matrix(matrix, record["robots"], heat_map_path)
  print(f"plot: {heat_map}")


def run_name(profile_name: str, family: str) -> str:
  """``smpl-exp1s-PROFILE`` on the default family, ``smpl-exp1s-FAMILY-PROFILE`` on another: how
  the file names of its records begin."""
  return "-".join(
    [f"smpl-{PROTOCOL}", *([family] if family != DEFAULT_FAMILY else []), profile_name]
  )


def record_path(record: dict, results: pathlib.Path) -> pathlib.Path:
  """``run_name``, then the record's date: ``smpl-exp1s-[FAMILY-]PROFILE-DATE.json``."""
  name = run_name(record["profile"], exp1s_records.family(record))
  return results / f"{name}-{provenance.date_stamp(record)}.json"
