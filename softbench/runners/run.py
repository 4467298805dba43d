"""``softbench run``: train (or reuse) an agent, evaluate it on a task over seeds, report.

For each seed the agent is built (learned agents train on the robot's babbling dataset, both
cached), then acts on one episode of the task (environment seed = the same seed); the episode's
errors per module are averaged over its steps, and the table gives their mean and standard
deviation over seeds. Every run writes a result record with full provenance.

With ``adaptive`` (task ``reach``, a learned agent), one agent (seed 0) reaches ``targets``
virtual targets with adaptive module activation instead (``softbench.runners.adaptive``); the record
then holds an ``adaptive`` section and no per-seed scores.

With ``faults`` (``--fault MODULE:ACTUATOR:GAIN``, ``softbench.robots.faults``) the agent is
built for the healthy robot, as a deployed controller would be, and evaluated on the faulty one.
"""

import dataclasses
import pathlib
import time

from smpl import training
from softbench import agents
from softbench import data
from softbench import episodes
from softbench import metrics
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import suite
from softbench import zoo
from softbench.agents import learned
from softbench.data import dataset
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import inverse as inverse_training
from softbench.records import fields
from softbench.records import provenance
from softbench.rendering import options as video_options
from softbench.rendering import replay
from softbench.rendering import video
from softbench.robots import faults as fault_model
from softbench.runners import adaptive as adaptive_activation
from softbench.runners import evaluation
from softbench.runners import parallel_seeds
from softbench.runners import saving
from softbench.runners.adaptive import experiment as adaptive_experiment
from softbench.runners.adaptive import report as adaptive_report
from softbench.runners.adaptive import runner as adaptive_runner
from softbench.suite import reach
from softbench.suite import trajectories

METRICS = (
  ("position_mm", "position (mm)"),
  ("orientation_deg", "orientation (deg)"),
  ("normalised_tip_percent", "tip error (%)"),
)
RECORD_FORMAT = records.FORMAT
RECORD_VERSION = records.VERSION


@dataclasses.dataclass(frozen=True)
class RunSettings:
  task: str
  agent: str
  robot: str
  seeds: int
  profile: profiles.Profile
  eval_mode: str
  trajectory: str | None = None
  module: int | None = None  # The reaching module (task reach); None: the task's default.
  adaptive: bool = False
  targets: int | None = None  # Virtual targets of an adaptive run.
  helpers: str | None = None  # How a learned agent completes partial targets (helper_targets of
  # LearnedAgent); None: the task gives whole targets, or the agent does not learn from babbling.
  faults: tuple[fault_model.Fault, ...] = ()
  given: str | None = None  # The part of a custom trajectory's targets its file gives (``Given``).


def settings(
  task: str,
  agent: str,
  robot: str | None = None,
  seeds: int | None = None,
  profile: str = profiles.DEFAULT_PROFILE,
  eval_mode: str = "physics",
  trajectory: str | None = None,
  module: int | None = None,
  adaptive: bool = False,
  targets: int | None = None,
  helpers: str | None = None,
  faults: tuple[str, ...] = (),
  given: str | None = None,
) -> RunSettings:
  """Checked settings, with the defaults filled in; ``faults`` as ``MODULE:ACTUATOR:GAIN`` text,
  ``given`` as ``suite.trajectories.Given`` text.

  Raises:
    ValueError: unknown task, agent, robot, profile or eval mode, seeds outside 1 ..
      ``profiles.MAX_SEEDS``, a trajectory
      without the custom task or the custom task without one, an unreadable or malformed
      trajectory file, a module with another task than reach or out of range, adaptive with
      another task than reach, a non-learned agent or more than one seed, targets without
      adaptive, targets < 1, unknown helpers or helpers where nothing is completed, a malformed
      fault or one that names no actuator of the robot, ``given`` without a trajectory or
      malformed (one line).
  """
  suite.describe(task)
  agents.describe(agent)
  chosen = profiles.get(profile)
  robot = robot or suite.describe(task).paper_robot
  parsed_faults = tuple(fault_model.parse(text) for text in faults)
  robots.make(robot).with_faults(parsed_faults)
  _check_adaptive(task, agent, robot, seeds, module, adaptive, targets)
  if adaptive and parsed_faults:
    raise ValueError("--fault and --adaptive do not go together yet")
  seeds = (1 if adaptive else chosen.seeds) if seeds is None else seeds
  dataset.check_count("seeds", seeds, profiles.MAX_SEEDS)
  if eval_mode not in fields.ERROR_SOURCES:
    raise ValueError(
      f"unknown eval mode {eval_mode!r}; choose one of {', '.join(fields.ERROR_SOURCES)}"
    )
  if (trajectory is None) == (task == "custom"):
    raise ValueError("--trajectory goes with --task custom, and --task custom needs one")
  if given is not None and trajectory is None:
    raise ValueError("--given goes with --task custom and its --trajectory")
  if given is not None:
    given = trajectories.Given.parse(given, robots.make(robot)).text
  if trajectory is not None:  # Read now: a bad file is refused before any collection or training.
    trajectories.load_trajectory(trajectory, robots.make(robot), given)
  if adaptive:
    targets = adaptive_activation.DEFAULT_TARGETS if targets is None else targets
  run = RunSettings(
    task,
    agent,
    robot,
    seeds,
    chosen,
    eval_mode,
    None if trajectory is None else str(trajectory),
    module,
    adaptive,
    targets,
    None,
    parsed_faults,
    given,
  )
  return dataclasses.replace(run, helpers=_helpers(run, helpers))


def _check_adaptive(
  task: str,
  agent: str,
  robot: str,
  seeds: int | None,
  module: int | None,
  adaptive: bool,
  targets: int | None,
) -> None:
  """The checks of ``--module``, ``--adaptive`` and ``--targets``."""
  if module is not None and task != "reach":
    raise ValueError("--module goes with --task reach")
  if module is not None:
    reach.check_module(robots.make(robot), module)
  if adaptive and task != "reach":
    raise ValueError(f"--adaptive goes with --task reach, not {task!r}: it reaches a point")
  if adaptive and agents.learner(agent) is None:
    raise ValueError(
      f"--adaptive needs an agent trained on babbling "
      f"({', '.join(agents.babbling_learners())}), not {agent!r}"
    )
  if adaptive and seeds not in (None, 1):
    raise ValueError("--adaptive uses one trained agent (seed 0); vary --targets, not --seeds")
  if targets is not None and not adaptive:
    raise ValueError("--targets goes with --adaptive")
  if targets is not None:
    dataset.check_count("targets", targets, adaptive_activation.MAX_TARGETS)


def _helpers(run: RunSettings, helpers: str | None) -> str | None:
  """How ``run``'s agent completes its task's partial targets: ``helpers``, or by default
  ``learned.DEFAULT_HELPER_TARGETS``; None where nothing is completed (whole targets, or an
  agent that does not learn from babbling).

  Raises:
    ValueError: unknown ``helpers``, or ``helpers`` where nothing is completed (one line).
  """
  if helpers is not None:
    adaptive_experiment.check_helpers(helpers)
  if suite.gives_whole_targets(run.robot, run.task, **task_options(run)):
    if helpers is not None:
      raise ValueError(f"--helpers completes partial targets; task {run.task!r} gives whole ones")
    return None
  if agents.learner(run.agent) is None:
    if helpers is not None:
      raise ValueError(
        f"--helpers goes with an agent trained on babbling "
        f"({', '.join(agents.babbling_learners())}), not {run.agent!r}"
      )
    return None
  return learned.DEFAULT_HELPER_TARGETS if helpers is None else helpers


def acting(run: RunSettings) -> learned.Acting:
  """How ``run``'s agent acts, if it is trained on babbling: its eval mode and helper targets."""
  return learned.Acting(run.eval_mode, run.helpers or learned.DEFAULT_HELPER_TARGETS)


def task_options(run: RunSettings) -> dict:
  """The options ``suite.load`` gets for ``run``'s task (episode length, trajectory and the
  part of it given)."""
  if run.task == "custom":
    return {"trajectory": run.trajectory, **({} if run.given is None else {"given": run.given})}
  options = {} if run.module is None else {"module": run.module}
  return {**options, **suite.length_options(run.task, run.profile.episode_length)}


@dataclasses.dataclass(frozen=True)
class VideoRequest:
  """An MP4 of seed 0's episode to render once the record is safe (``--video``)."""

  path: pathlib.Path
  options: video_options.VideoOptions


def write_video(
  run: RunSettings, seed: int, episode: episodes.Episode, request: VideoRequest
) -> None:
  """Renders ``episode`` (seed ``seed`` of ``run``) as ``request`` asks; prints what it wrote."""
  stats = video.render(replay_of(run, seed, episode), request.path, request.options, True)
  print(stats.describe(request.options))


def render_seed(run: RunSettings, seed: int, request: VideoRequest) -> None:
  """``softbench render``: trains (or reuses) seed ``seed``'s agent, runs its episode with a
  progress bar and renders it as ``request`` asks."""
  write_video(run, seed, seed_episode(run, seed, show_progress=True), request)


def finish(
  run: RunSettings,
  record: dict,
  files: list[pathlib.Path],
  episodes_run: list[episodes.Episode],
  video_request: VideoRequest | None = None,
) -> None:
  """What follows a saved record (``files``, the results folder's first): the finished seeds
  kept for resuming go (only now: a failed write leaves a run that resumes), then the plots,
  then the video, which the record files then link."""
  # Plotting imports matplotlib (0.7 s), which no seed worker or Ray task needs: not at the top.
  from softbench import plots
  from softbench.runners.adaptive import plot as adaptive_plot

  episode_snapshots.discard(run)
  if run.adaptive:
    print(f"plot: {adaptive_plot.write(record, files[0].with_suffix('.png'))}")
  for plot in plots.save_run_plots(files[0], record, episodes_run) if episodes_run else ():
    print(f"plot: {plot}")
  if video_request is not None:
    write_video(run, 0, episodes_run[0], video_request)
    saving.link_video(record, files, video_request.path)


def replay_of(run: RunSettings, seed: int, episode: episodes.Episode) -> replay.Replay:
  """The replay of ``episode``, seed ``seed`` of ``run``, for videos."""
  feedback = "" if run.eval_mode == "physics" else f", eval {run.eval_mode}"
  return replay.Replay(
    robots.make(run.robot),
    run.task,
    seed,
    task_options(run),
    episode,
    f"{run.agent} on {run.task} ({run.robot}) seed {seed}, {run.profile.name} profile{feedback}",
  )


def _seed_scores(score: metrics.TrackingScore) -> dict:
  """Per-module means over the episode's steps, and their average over modules."""
  result = {}
  for name, _ in METRICS:
    per_module = getattr(score, name)
    if per_module:
      result[name] = {
        "per_module": [s.mean for s in per_module],
        "per_module_std_over_steps": [s.std for s in per_module],
        "mean": score.average(name).mean,
      }
  return result


def episode_on(
  agent: agents.Agent,
  arm: robots.SoftArm,
  run: RunSettings,
  seed: int,
  show_progress: bool = False,
  unfinished: pathlib.Path | None = None,
) -> episodes.Episode:
  """One episode of ``run``'s task (environment seed ``seed``) by ``agent`` on ``arm``, which may
  be a faulty robot; kept while it runs at ``unfinished`` (``evaluation.run_episode``)."""
  if isinstance(agent, learned.LearnedAgent) and agent.acting != acting(run):
    raise ValueError(f"this agent acts as {agent.acting}, but the run asks for {acting(run)}")
  env = suite.load(arm, run.task, seed=seed, **task_options(run))
  return evaluation.run_episode(env, agent, run.task, show_progress, unfinished)


def seed_entry(seed: int, episode: episodes.Episode, arm: robots.SoftArm) -> dict:
  """The record's entry of one seed's episode."""
  return {
    "seed": seed,
    "steps": len(episode.actions),
    "mean_reward": float(episode.rewards.mean()),
    **_seed_scores(episode.score(arm.length)),
  }


def evaluate(
  agent: agents.Agent, arm: robots.SoftArm, run: RunSettings, seed: int, show_progress: bool = False
) -> tuple[dict, tuple[int, ...]]:
  """``episode_on``, scored: the seed's record entry and the scored modules."""
  episode = episode_on(agent, arm, run, seed, show_progress)
  return seed_entry(seed, episode, arm), episode.scored_modules


def seed_episode(run: RunSettings, seed: int, show_progress: bool = False) -> episodes.Episode:
  """Builds (trains) the agent of ``seed`` for the healthy robot, as a deployed controller would
  be, and runs it through one episode on the robot with ``run.faults``."""
  return _episode_and_arm(run, seed, show_progress)[0]


def _episode_and_arm(
  run: RunSettings, seed: int, show_progress: bool, unfinished: pathlib.Path | None = None
) -> tuple[episodes.Episode, robots.SoftArm]:
  """``seed_episode``, and the (faulty) robot it ran on."""
  arm = robots.make(run.robot)
  agent = agents.make(run.agent, arm, seed, run.profile, show_progress, acting(run))
  faulty = arm.with_faults(run.faults)
  return episode_on(agent, faulty, run, seed, show_progress, unfinished), faulty


def score_seed(run: RunSettings, seed: int) -> dict:
  """``seed_episode``'s record entry, without progress bars or kept episodes."""
  episode, arm = _episode_and_arm(run, seed, False)
  return seed_entry(seed, episode, arm)


def resumed_seed(run: RunSettings, seed: int) -> tuple[dict, episodes.Episode] | None:
  """The episode of ``seed`` that an interrupted run of the same settings and code saved, with its
  record entry; None if there is none."""
  episode = episode_snapshots.load(run, seed)
  if episode is None:
    return None
  return seed_entry(seed, episode, robots.make(run.robot).with_faults(run.faults)), episode


def fresh_seed(
  run: RunSettings, seed: int, show_progress: bool = False
) -> tuple[dict, episodes.Episode]:
  """``seed_episode``'s record entry, checked to be finite (a record must hold it), and the
  episode; an episode of an agent that can resume one is kept while it runs
  (``episode_snapshots.partial_path``), and an interrupted one goes on."""
  unfinished = episode_snapshots.partial_path(run, seed)
  episode, arm = _episode_and_arm(run, seed, show_progress, unfinished)
  entry = seed_entry(seed, episode, arm)
  records.check_finite(entry, f"seed {seed}'s scores")
  return entry, episode


def _run_seed(seed: int, run: RunSettings, show_progress: bool) -> tuple[dict, episodes.Episode]:
  """The record entry and episode of ``seed``: ``resumed_seed``, else ``fresh_seed``, whose
  episode is saved at once for a later run to resume from."""
  outcome = resumed_seed(run, seed)
  if outcome is None:
    outcome = fresh_seed(run, seed, show_progress)
    episode_snapshots.save(run, seed, outcome[1])
  return outcome


def weight_files(run: RunSettings) -> list[list[pathlib.Path]]:
  """Per seed, the cache files a babbling learner of ``run`` is made of (checkpoint, forward
  models); none for the other agents."""
  learner = agents.learner(run.agent)
  if learner is None:
    return []
  arm = robots.make(run.robot)
  return [
    [path for path, _ in learned.cache_files(run.agent, arm, seed, run.profile, learner.per_module)]
    for seed in range(run.seeds)
  ]


def take_from_zoo(run: RunSettings) -> tuple[list[str], bool]:
  """For an agent trained on babbling, the zoo files taken for the checkpoints of ``run``'s seeds
  that the data home lacks (``zoo.take``), and whether every one is now in the data home; for
  the other agents nothing, and False."""
  learner = agents.learner(run.agent)
  if learner is None:
    return [], False
  arm = robots.make(run.robot)
  return zoo.take(
    [
      learned.checkpoint_path(run.agent, arm, seed, run.profile, learner.per_module)
      for seed in range(run.seeds)
    ]
  )


def execute(run: RunSettings, show_progress: bool = True, workers: int | None = None) -> dict:
  """Runs every seed, in parallel processes on every core, and returns the result record.

  The babbling dataset is collected first (on every core), so that the seeds share it.
  """
  return execute_episodes(run, show_progress, workers)[0]


def execute_episodes(
  run: RunSettings, show_progress: bool = True, workers: int | None = None, keep_seeds: bool = False
) -> tuple[dict, list[episodes.Episode]]:
  """``execute``, also returning every seed's episode (in seed order) for plots and videos;
  a learned agent's checkpoints that the data home lacks are taken from the zoo where it holds
  them (``softbench.zoo``; the record then names them in a ``zoo`` section), and the babbling
  dataset is collected only if some seed still has to train;
  none for an adaptive run (``softbench.runners.adaptive`` draws its own figure). The finished seeds
  kept for resuming are discarded at the end unless ``keep_seeds``: then the caller discards
  them (``episode_snapshots.discard``) once the record is safely written."""
  started = time.perf_counter()
  origin = provenance.provenance(str(training.default_device()))
  taken, trained = take_from_zoo(run)
  learns = agents.learner(run.agent) is not None or agents.describe(run.agent).learned
  if learns and not trained:  # Some seed trains on babbling (or acts towards its targets, sac).
    data.collect(
      run.robot,
      samples=run.profile.samples,
      seed=inverse_training.DATA_SEED,
      progress=show_progress,
    )
  if run.adaptive:
    section = adaptive_runner.run(
      run.robot,
      run.agent,
      run.profile,
      run.targets,
      run.module,
      run.eval_mode,
      run.helpers,
      show_progress,
    )
    return assemble_record(run, origin, [], taken, time.perf_counter() - started, section), []
  if show_progress:
    episode_snapshots.report_resuming(episode_snapshots.folder(run), run.seeds)
  outcomes = parallel_seeds.over_seeds(
    _run_seed, run.seeds, (run,), f"{run.agent} on {run.task}", show_progress, workers
  )
  if not keep_seeds:
    episode_snapshots.discard(run)
  record = assemble_record(run, origin, outcomes, taken, time.perf_counter() - started)
  return record, [episode for _, episode in outcomes]


def assemble_record(
  run: RunSettings,
  origin: dict,
  outcomes: list[tuple[dict, episodes.Episode]],
  taken: list[str],
  wall_time_s: float,
  adaptive: dict | None = None,
) -> dict:
  """The result record of ``run``: its provenance ``origin`` (``records.provenance``) and
  settings, every seed's entry and the scored modules from ``outcomes`` (seed order), what an
  agent that learns by acting spent on each seed's training (read from its cache), the zoo files
  ``taken`` for it, the sha256 of each seed's weight files (``zoo.weights_section``) and
  ``wall_time_s``; for an adaptive run its ``adaptive`` section instead of
  per-seed scores."""
  arm = robots.make(run.robot)
  if adaptive is not None:
    results = {"scored_modules": [adaptive["target_module"]], "per_seed": [], "adaptive": adaptive}
  else:
    results = {
      "scored_modules": list(outcomes[0][1].scored_modules),
      "per_seed": [entry for entry, _ in outcomes],
    }
    spent = [
      agents.training_summary(run.agent, arm, seed, run.profile) for seed in range(run.seeds)
    ]
    if any(summary is not None for summary in spent):  # An agent that learns by acting.
      results["training"] = {
        "per_seed": [{"seed": seed, **(summary or {})} for seed, summary in enumerate(spent)]
      }
  return {
    "format": RECORD_FORMAT,
    "version": RECORD_VERSION,
    **origin,
    "robot": run.robot,
    "task": run.task,
    "agent": run.agent,
    "profile": run.profile.name,
    "profile_settings": dataclasses.asdict(run.profile),
    "eval_mode": run.eval_mode,
    "trajectory": run.trajectory,
    **({} if run.given is None else {"given": run.given}),
    **({} if run.helpers is None or adaptive is not None else {"helpers": run.helpers}),
    "seeds": run.seeds,
    "faults": [fault_model.describe(arm, fault) for fault in run.faults],
    **results,
    **zoo.section(taken),
    **zoo.weights_section(weight_files(run)),
    "wall_time_s": round(wall_time_s, 3),
  }


def summary(record: dict, metric: str) -> tuple[list[metrics.Statistic], metrics.Statistic]:
  """Per-module and module-averaged mean and standard deviation over seeds of ``metric``."""
  seeds = [entry[metric] for entry in record["per_seed"] if metric in entry]
  per_module = [
    metrics.Statistic.of([entry["per_module"][k] for entry in seeds])
    for k in range(len(seeds[0]["per_module"]))
  ]
  return per_module, metrics.Statistic.of([entry["mean"] for entry in seeds])


def table(record: dict) -> str:
  """The printed table: rows per scored module and their mean, columns per metric (an adaptive
  run: ``softbench.runners.adaptive.report.table``)."""
  if "adaptive" in record:
    return adaptive_report.table(record)
  measured = [(name, label) for name, label in METRICS if name in record["per_seed"][0]]
  columns = {name: summary(record, name) for name, _ in measured}
  rows = [f"module {module}" for module in record["scored_modules"]] + ["mean"]
  header = f"{'':<10}" + "".join(f"{label:>22}" for _, label in measured)
  faulty = record.get("faults") or []
  under = f" under fault {', '.join(fault['text'] for fault in faulty)}" if faulty else ""
  lines = [
    f"{record['agent']} on {record['task']} ({record['robot']}{under}), profile "
    f"{record['profile']}, eval {record['eval_mode']}, {record['seeds']} seed(s): "
    f"mean ± std over seeds",
    header,
  ]
  for index, row in enumerate(rows):
    cells = []
    for name, _ in measured:
      per_module, average = columns[name]
      statistic = average if index == len(rows) - 1 else per_module[index]
      decimals = metrics.decimals_of(statistic.mean)  # Micrometres too: 0.00940, not 0.01.
      mean, std = (metrics.number(value, decimals) for value in (statistic.mean, statistic.std))
      cells.append(f"{mean:>13} ± {std:<6}")
    lines.append(f"{row:<10}" + "".join(cells))
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)


def record_path(record: dict, results: pathlib.Path) -> pathlib.Path:
  task = record["task"] + ("-adaptive" if "adaptive" in record else "")
  faulty = "".join(
    f"-fault{fault['module']}.{fault['actuator']}.{fault['gain']:g}"
    for fault in record.get("faults") or []
  )
  return results / (
    f"{record['agent']}-{record['robot']}{faulty}-{task}-{record['profile']}-"
    f"{record['eval_mode']}-{provenance.date_stamp(record)}.json"
  )
