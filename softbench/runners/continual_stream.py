"""``softbench run --protocol continual``: a continual strategy learns a stream, and after every
stage every configuration seen so far is scored in physics.

Per seed (seeds in parallel processes), stage after stage (``softbench.continual.learning``,
cached per stage): the strategy learns, then each configuration c <= s runs one closed-loop
episode of the stream's task on its robot, driven by the strategy's controller for c, and its
end effector is scored (mean over the episode). An episode whose controller reads the same
weights as one already run (``Strategy.controller_digest``: SMPL's frozen columns, ``independent``'s
networks, ``joint`` after its one training) is not run again: the same weights on the same seeded
episode give the same scores. Finished episodes are kept (``episodes.snapshots``) until the record
is written, so an interrupted run resumes.
"""

import dataclasses
import pathlib
import time
from typing import Sequence

import numpy as np

from smpl import fitting
from softbench import data
from softbench import metrics
from softbench import profiles
from softbench import suite
from softbench.agents import base as base_agent
from softbench.agents import learned
from softbench.continual import learning as continual_learning
from softbench.continual import metrics as continual_metrics
from softbench.continual import strategies
from softbench.continual import streams
from softbench.continual.strategies import base as strategy_base
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import inverse as inverse_training
from softbench.records import provenance
from softbench.records.continual import FORMAT as RECORD_FORMAT
from softbench.records.continual import PROTOCOL
from softbench.records.continual import VERSION as RECORD_VERSION
from softbench.records.exp1s import DEFAULT_FAMILY
from softbench.runners import continual as exp1s_runner
from softbench.runners import evaluation
from softbench.runners import parallel_seeds


@dataclasses.dataclass(frozen=True)
class ContinualSettings:
  """A checked ``softbench run --protocol continual``."""

  strategy: str
  stream: str
  family: str
  profile: profiles.Profile
  seeds: int


def settings(
  strategy: str,
  stream: str | None,
  profile: str = profiles.DEFAULT_PROFILE,
  family: str | None = None,
  seeds: int | None = None,
  eval_mode: str = "physics",
  task_options: Sequence[str] = (),
) -> ContinualSettings:
  """Checked settings, the seeds resolved (None: the profile's).

  Raises:
    ValueError: no or an unknown stream, an unknown strategy, family or profile, a strategy
      that cannot run the stream, a task run's option, another eval mode, seeds out of range
      (one line).
  """
  if stream is None:
    raise ValueError(
      f"--protocol {PROTOCOL} needs --stream STREAM, one of {', '.join(streams.STREAMS)}"
    )
  chosen_stream = streams.get(stream)
  strategies.describe(strategy)
  exp1s_runner.check_fixed_options(
    PROTOCOL, "its robots, task and loop (the stream's)", task_options, eval_mode
  )
  chosen = profiles.get(profile)
  family = family or DEFAULT_FAMILY
  configurations = chosen_stream.configurations(family)
  strategies.strategy_class(strategy).check(configurations)
  return ContinualSettings(strategy, stream, family, chosen, exp1s_runner.seed_count(chosen, seeds))


def episodes_folder(run: ContinualSettings) -> pathlib.Path:
  """Where the finished episodes' scores of ``run`` are kept until its record is written (keyed
  by the settings and the code)."""
  settings_without_seeds = dataclasses.replace(run, seeds=0)
  return episode_snapshots.keyed_folder(
    f"{run.strategy}-{PROTOCOL}-{run.stream}", dataclasses.asdict(settings_without_seeds)
  )


def configuration_agent(
  strategy: strategy_base.Strategy,
  stage: strategy_base.StageData,
  configuration: int,
  seed: int,
) -> learned.LearnedAgent:
  """The agent that drives ``configuration``'s arm with ``strategy``'s controller for it, closed
  loop in physics through the configuration's forward model (``stage``)."""
  robot = stage.configuration.robot
  controller = learned.Controller(
    data.View.end_effector(robot), stage.forward.cpu().eval(), stage.windows.normalisation
  )
  return learned.LearnedAgent(
    robot, seed, strategy.controller(configuration), [controller], learned.Acting("physics")
  )


def end_effector_episode(
  agent: base_agent.Agent,
  task: str,
  seed: int,
  profile: profiles.Profile,
  show_progress: bool = False,
) -> dict:
  """The end-effector scores of one seeded episode of ``task`` that ``agent`` drives on its
  robot, as a stage's configuration is scored."""
  robot = agent.robot
  env = suite.load(robot, task, seed=seed, **suite.length_options(task, profile.episode_length))
  episode = evaluation.run_episode(env, agent, task, show_progress)
  return exp1s_runner.end_effector_scores(episode, robot.length)


def score_configuration(
  strategy: strategy_base.Strategy,
  stage: strategy_base.StageData,
  configuration: int,
  seed: int,
  run: ContinualSettings,
  kept: pathlib.Path,
  show_progress: bool,
) -> dict:
  """Configuration ``configuration``'s end-effector scores, driven by ``strategy`` now: kept
  from an earlier episode with the same weights, or run now."""
  digest = strategy.controller_digest(configuration)
  path = kept / f"seed{seed}-configuration{configuration}-{digest[:24]}.json"
  subject = f"seed {seed}'s episode of configuration {configuration + 1}"
  found = episode_snapshots.load_scores(path, subject)
  if found is not None:
    return found
  agent = configuration_agent(strategy, stage, configuration, seed)
  task = streams.get(run.stream).task
  scores = end_effector_episode(agent, task, seed, run.profile, show_progress)
  episode_snapshots.save_scores(path, scores, subject)
  return scores


def run_seed(seed: int, run: ContinualSettings, show_progress: bool = False) -> dict:
  """Seed ``seed``: every stage's summary (``continual.learning.learn``) with the physics
  scores of configurations 0..s after it."""
  kept = episodes_folder(run)
  entries = []
  for strategy, stages, summary in continual_learning.learn(
    run.strategy, streams.get(run.stream), run.family, seed, run.profile, show_progress
  ):
    scores = [
      score_configuration(strategy, stages[c], c, seed, run, kept, show_progress)
      for c in range(summary["stage"] + 1)
    ]
    entries.append({**summary, "scores": scores})
  return {"seed": seed, "stages": entries}


def execute(
  run: ContinualSettings,
  show_progress: bool = True,
  workers: int | None = None,
  keep_seeds: bool = False,
) -> dict:
  """Every seed (in parallel processes), then the record with full provenance. The kept
  episodes are discarded at the end unless ``keep_seeds`` (then ``finish`` discards them once
  the record is written)."""
  started = time.perf_counter()
  origin = provenance.provenance(str(fitting.default_device()))
  configurations = streams.get(run.stream).configurations(run.family)
  for configuration in configurations:  # Every core, before the seeds.
    data.collect(
      configuration.robot,
      samples=run.profile.samples,
      seed=inverse_training.DATA_SEED,
      progress=show_progress,
    )
  per_seed = parallel_seeds.over_seeds(
    run_seed,
    run.seeds,
    (run,),
    f"{run.strategy} {PROTOCOL} {run.stream}",
    show_progress,
    workers,
  )
  if not keep_seeds:
    episode_snapshots.discard_folder(episodes_folder(run))
  return assemble_record(run, origin, per_seed, time.perf_counter() - started)


def assemble_record(
  run: ContinualSettings, origin: dict, per_seed: list[dict], wall_time_s: float
) -> dict:
  """The record of ``run``: provenance ``origin`` (``records.provenance``), every seed's entry
  (``run_seed``, seed order) and ``wall_time_s``."""
  configurations = streams.get(run.stream).configurations(run.family)
  return {
    "format": RECORD_FORMAT,
    "version": RECORD_VERSION,
    **origin,
    "protocol": PROTOCOL,
    "agent": run.strategy,
    "stream": run.stream,
    "family": run.family,
    "task": streams.get(run.stream).task,
    "configurations": [configuration.describe() for configuration in configurations],
    "profile": run.profile.name,
    "profile_settings": dataclasses.asdict(run.profile),
    "seeds": run.seeds,
    "per_seed": per_seed,
    "wall_time_s": round(wall_time_s, 3),
  }


def _cell(values) -> str:
  statistic = metrics.Statistic.of(values)
  return metrics.mean_and_std(statistic.mean, statistic.std)


def table(record: dict) -> str:
  """The stage x configuration error matrix (mm, mean ± std over seeds), the average final
  error and forgetting (mm and % of length), then each stage's training: data, epochs, time and
  parameters."""
  labels = [configuration["label"] for configuration in record["configurations"]]
  width = max(16, *(len(label) + 2 for label in labels))
  per_seed = continual_metrics.matrices(record)
  lines = [
    f"{record['agent']} on stream {record['stream']} ({record['family']}), profile "
    f"{record['profile']}, {record['seeds']} seed(s): end-effector position error (mm) on "
    f"{record['task']}, closed loop in physics, of each configuration (columns) after each stage "
    f"(rows); mean ± std over seeds",
    f"{'after':<16}" + "".join(f"{label:>{width}}" for label in labels),
  ]
  for stage, label in enumerate(labels):
    cells = [_cell(per_seed[:, stage, c]) if c <= stage else "" for c in range(len(labels))]
    lines.append(f"{label:<16}" + "".join(f"{cell:>{width}}" for cell in cells))
  lines.append("")
  for unit in continual_metrics.METRIC_FIELDS:
    summary = continual_metrics.summary(record, unit)
    final, forgetting = summary["average_final"], summary["forgetting"]
    lines.append(
      f"average final error {metrics.mean_and_std(final.mean, final.std)} {unit}, "
      f"forgetting {metrics.mean_and_std(forgetting.mean, forgetting.std)} {unit}"
    )
  columns = ("trained on", 16), ("epochs", 10), ("seconds", 12), ("parameters", 14), ("trained", 12)
  lines += ["", f"{'stage':<16}" + "".join(f"{name:>{width}}" for name, width in columns)]
  for stage, label in enumerate(labels):
    entries = [seed["stages"][stage] for seed in record["per_seed"]]
    trained_on = ",".join(str(c + 1) for c in entries[0]["trained_on"]) or "-"
    epochs = np.mean([sum(entry["epochs"]) for entry in entries])
    seconds = np.mean([entry["training_seconds"] for entry in entries])
    lines.append(
      f"{label:<16}{trained_on:>16}{epochs:>10.1f}{seconds:>12.1f}"
      f"{entries[0]['parameters']:>14,}{entries[0]['parameters_trained']:>12,}"
    )
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)


def run_name(strategy: str, stream: str, family: str, profile_name: str) -> str:
  """``STRATEGY-continual-STREAM[-FAMILY]-PROFILE``: how its record files begin."""
  family_part = [family] if family != DEFAULT_FAMILY else []
  return "-".join([strategy, PROTOCOL, stream, *family_part, profile_name])


def record_path(record: dict, results: pathlib.Path) -> pathlib.Path:
  name = run_name(record["agent"], record["stream"], record["family"], record["profile"])
  return results / f"{name}-{provenance.date_stamp(record)}.json"


def _kept_seed_file(run: ContinualSettings, seed: int) -> tuple[pathlib.Path, str]:
  return episodes_folder(run) / f"seed{seed}.json", f"seed {seed}"


def kept_seed(run: ContinualSettings, seed: int) -> dict | None:
  """The entry of ``seed`` (``run_seed``) that an interrupted sweep of ``run`` kept; None if
  there is none (or it is damaged: reported on one line)."""
  return episode_snapshots.load_scores(*_kept_seed_file(run, seed))


def keep_seed(run: ContinualSettings, seed: int, entry: dict) -> None:
  """Keeps the entry of ``seed`` until the record of ``run`` is written (``finish``)."""
  episode_snapshots.save_scores(*_kept_seed_file(run, seed), entry)


def stage_files(run: ContinualSettings, seed: int) -> list[pathlib.Path]:
  """The cached state of every stage of ``seed`` (``continual.learning``), once learned."""
  stream = streams.get(run.stream)
  configurations = stream.configurations(run.family)
  folder = continual_learning.folder(
    continual_learning.config(run.strategy, run.stream, configurations, seed, run.profile)
  )
  return [continual_learning.stage_path(folder, stage) for stage in range(len(configurations))]


def finish(run: ContinualSettings, record: dict, files: list[pathlib.Path]) -> None:
  """What follows a saved record: the kept episodes go, then the heat map of the mean error
  matrix (% of length) beside the record."""
  from softbench import plots  # Not at the top: no seed worker needs it.

  episode_snapshots.discard_folder(episodes_folder(run))
  path = files[0]
  heat_map = plots.forgetting_matrix(
    np.mean(continual_metrics.matrices(record, "%"), axis=0),
    [configuration["label"] for configuration in record["configurations"]],
    path.with_name(f"{path.stem}-matrix.png"),
    title=f"{record['agent']} on {record['stream']}: normalised tip error (%) after each stage",
  )
  print(f"plot: {heat_map}")
