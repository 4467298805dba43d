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

from smpl import fitting
from softbench import agents
from softbench import data
from softbench import episodes
from softbench import metrics
from softbench import records
from softbench import robots
from softbench import suite
from softbench import zoo
from softbench.agents import learned
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import inverse as inverse_training
from softbench.records import provenance
from softbench.rendering import options as video_options
from softbench.rendering import replay
from softbench.rendering import video
from softbench.robots import faults as fault_model
from softbench.runners import evaluation
from softbench.runners import parallel_seeds
from softbench.runners import run_settings
from softbench.runners import saving
from softbench.runners.adaptive import report as adaptive_report
from softbench.runners.adaptive import runner as adaptive_runner

METRICS = (
  ("position_mm", "position (mm)"),
  ("orientation_deg", "orientation (deg)"),
  ("normalised_tip_percent", "tip error (%)"),
)
RECORD_FORMAT = records.FORMAT
RECORD_VERSION = records.VERSION


@dataclasses.dataclass(frozen=True)
class VideoRequest:
  """An MP4 of seed 0's episode to render once the record is safe (``--video``)."""

  path: pathlib.Path
  options: video_options.VideoOptions


def write_video(
  run: run_settings.RunSettings, seed: int, episode: episodes.Episode, request: VideoRequest
) -> None:
  """Renders ``episode`` (seed ``seed`` of ``run``) as ``request`` asks; prints what it wrote."""
  stats = video.render(replay_of(run, seed, episode), request.path, request.options, True)
  print(stats.describe(request.options))


def render_seed(run: run_settings.RunSettings, seed: int, request: VideoRequest) -> None:
  """``softbench render``: trains (or reuses) seed ``seed``'s agent, runs its episode with a
  progress bar and renders it as ``request`` asks."""
  write_video(run, seed, seed_episode(run, seed, show_progress=True), request)


def finish(
  run: run_settings.RunSettings,
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


def replay_of(run: run_settings.RunSettings, seed: int, episode: episodes.Episode) -> replay.Replay:
  """The replay of ``episode``, seed ``seed`` of ``run``, for videos."""
  feedback = "" if run.eval_mode == "physics" else f", eval {run.eval_mode}"
  return replay.Replay(
    robots.make(run.robot),
    run.task,
    seed,
    run_settings.task_options(run),
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
  run: run_settings.RunSettings,
  seed: int,
  show_progress: bool = False,
  unfinished: pathlib.Path | None = None,
) -> episodes.Episode:
  """One episode of ``run``'s task (environment seed ``seed``) by ``agent`` on ``arm``, which may
  be a faulty robot; kept while it runs at ``unfinished`` (``evaluation.run_episode``)."""
  asked = run_settings.acting(run)
  if isinstance(agent, learned.LearnedAgent) and agent.acting != asked:
    raise ValueError(f"this agent acts as {agent.acting}, but the run asks for {asked}")
  env = suite.load(arm, run.task, seed=seed, **run_settings.task_options(run))
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
  agent: agents.Agent,
  arm: robots.SoftArm,
  run: run_settings.RunSettings,
  seed: int,
  show_progress: bool = False,
) -> tuple[dict, tuple[int, ...]]:
  """``episode_on``, scored: the seed's record entry and the scored modules."""
  episode = episode_on(agent, arm, run, seed, show_progress)
  return seed_entry(seed, episode, arm), episode.scored_modules


def seed_episode(
  run: run_settings.RunSettings, seed: int, show_progress: bool = False
) -> episodes.Episode:
  """Builds (trains) the agent of ``seed`` for the healthy robot, as a deployed controller would
  be, and runs it through one episode on the robot with ``run.faults``."""
  return _episode_and_arm(run, seed, show_progress)[0]


def _episode_and_arm(
  run: run_settings.RunSettings,
  seed: int,
  show_progress: bool,
  unfinished: pathlib.Path | None = None,
) -> tuple[episodes.Episode, robots.SoftArm]:
  """``seed_episode``, and the (faulty) robot it ran on."""
  arm = robots.make(run.robot)
  agent = agents.make(run.agent, arm, seed, run.profile, show_progress, run_settings.acting(run))
  faulty = arm.with_faults(run.faults)
  return episode_on(agent, faulty, run, seed, show_progress, unfinished), faulty


def score_seed(run: run_settings.RunSettings, seed: int) -> dict:
  """``seed_episode``'s record entry, without progress bars or kept episodes."""
  episode, arm = _episode_and_arm(run, seed, False)
  return seed_entry(seed, episode, arm)


def resumed_seed(run: run_settings.RunSettings, seed: int) -> tuple[dict, episodes.Episode] | None:
  """The episode of ``seed`` that an interrupted run of the same settings and code saved, with its
  record entry; None if there is none."""
  episode = episode_snapshots.load(run, seed)
  if episode is None:
    return None
  return seed_entry(seed, episode, robots.make(run.robot).with_faults(run.faults)), episode


def fresh_seed(
  run: run_settings.RunSettings, seed: int, show_progress: bool = False
) -> tuple[dict, episodes.Episode]:
  """``seed_episode``'s record entry, checked to be finite (a record must hold it), and the
  episode; an episode of an agent that can resume one is kept while it runs
  (``episodes.snapshots.partial_path``), and an interrupted one goes on."""
  unfinished = episode_snapshots.partial_path(run, seed)
  episode, arm = _episode_and_arm(run, seed, show_progress, unfinished)
  entry = seed_entry(seed, episode, arm)
  records.check_finite(entry, f"seed {seed}'s scores")
  return entry, episode


def _run_seed(
  seed: int, run: run_settings.RunSettings, show_progress: bool
) -> tuple[dict, episodes.Episode]:
  """The record entry and episode of ``seed``: ``resumed_seed``, else ``fresh_seed``, whose
  episode is saved at once for a later run to resume from."""
  outcome = resumed_seed(run, seed)
  if outcome is None:
    outcome = fresh_seed(run, seed, show_progress)
    episode_snapshots.save(run, seed, outcome[1])
  return outcome


def weight_files(run: run_settings.RunSettings) -> list[list[pathlib.Path]]:
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


def take_from_zoo(run: run_settings.RunSettings) -> tuple[list[str], bool]:
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


def execute(
  run: run_settings.RunSettings, show_progress: bool = True, workers: int | None = None
) -> dict:
  """Runs every seed, in parallel processes on every core, and returns the result record.

  The babbling dataset is collected first (on every core), so that the seeds share it.
  """
  return execute_episodes(run, show_progress, workers)[0]


def execute_episodes(
  run: run_settings.RunSettings,
  show_progress: bool = True,
  workers: int | None = None,
  keep_seeds: bool = False,
) -> tuple[dict, list[episodes.Episode]]:
  """``execute``, also returning every seed's episode (in seed order) for plots and videos;
  a learned agent's checkpoints that the data home lacks are taken from the zoo where it holds
  them (``softbench.zoo``; the record then names them in a ``zoo`` section), and the babbling
  dataset is collected only if some seed still has to train;
  none for an adaptive run (``softbench.runners.adaptive`` draws its own figure). The finished seeds
  kept for resuming are discarded at the end unless ``keep_seeds``: then the caller discards
  them (``episode_snapshots.discard``) once the record is safely written."""
  started = time.perf_counter()
  origin = provenance.provenance(str(fitting.default_device()))
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
  run: run_settings.RunSettings,
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
