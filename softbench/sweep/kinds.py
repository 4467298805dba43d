"""What a sweep does differently for each kind of setting: a task's run
(``run_settings.RunSettings``), an Exp1S run (``continual.Exp1sSettings``) or a continual
strategy on a stream (``continual_stream.ContinualSettings``). ``of(run)`` gives the kind of a
setting; the planner, the workers and the driver ask it, never the setting's type."""

from softbench import episodes
from softbench import storage
from softbench import zoo
from softbench.continual import streams
from softbench.episodes import snapshots as episode_snapshots
from softbench.runners import continual
from softbench.runners import continual_stream
from softbench.runners import run as run_module
from softbench.runners import run_settings
from softbench.runners import saving
from softbench.sweep import builds

Setting = run_settings.RunSettings | continual.Exp1sSettings | continual_stream.ContinualSettings


class TaskRuns:
  """A task's run: one episode per seed by an agent built once per robot and seed."""

  @staticmethod
  def name(run: run_settings.RunSettings) -> str:
    return f"{run.agent}-{run.robot}-{run.task}-{run.profile.name}-{run.eval_mode}"

  @staticmethod
  def unnamed_settings(run: run_settings.RunSettings) -> dict:
    return {"seeds": run.seeds, "helpers": run.helpers}

  @staticmethod
  def zoo_key(run: run_settings.RunSettings) -> tuple:
    return (run.agent, run.robot, run.profile, run.seeds)

  @staticmethod
  def take_from_zoo(run: run_settings.RunSettings) -> list[str]:
    return run_module.take_from_zoo(run)[0]

  @staticmethod
  def resumed_seed(run: run_settings.RunSettings, seed: int):
    return run_module.resumed_seed(run, seed)

  @staticmethod
  def seed_build(run: run_settings.RunSettings, seed: int) -> builds.Build | None:
    return builds.agent_build(run.agent, run.robot, seed, run.profile)

  @staticmethod
  def evaluate(run: run_settings.RunSettings, seed: int) -> tuple[dict, episodes.Episode]:
    return run_module.fresh_seed(run, seed)

  @staticmethod
  def keep(run: run_settings.RunSettings, seed: int, outcome) -> None:
    episode_snapshots.save(run, seed, outcome[1])

  @staticmethod
  def save(run, origin: dict, outcomes: list, taken: list[str], wall_time_s: float, results):
    record = run_module.assemble_record(run, origin, outcomes, taken, wall_time_s)
    files = saving.save(run_module, record, results, ends_command=False)
    episode_snapshots.discard(run)
    return files


class Exp1sRuns:
  """An Exp1S run: each seed's network built once, then its scores."""

  @staticmethod
  def name(run: continual.Exp1sSettings) -> str:
    return continual.run_name(run.profile.name, run.family)

  @staticmethod
  def unnamed_settings(run: continual.Exp1sSettings) -> dict:
    return {"seeds": run.seeds}

  @staticmethod
  def zoo_key(run: continual.Exp1sSettings):
    return run

  @staticmethod
  def take_from_zoo(run: continual.Exp1sSettings) -> list[str]:
    paths = [continual.checkpoint_path(seed, run.profile, run.family) for seed in range(run.seeds)]
    return zoo.take(paths)[0]

  @staticmethod
  def resumed_seed(run: continual.Exp1sSettings, seed: int) -> dict | None:
    return continual.kept_scores(run, seed)

  @staticmethod
  def seed_build(run: continual.Exp1sSettings, seed: int) -> builds.Build:
    return builds.network_build(run, seed)

  @staticmethod
  def evaluate(run: continual.Exp1sSettings, seed: int) -> dict:
    return continual.run_seed(seed, run.profile, run.family)

  @staticmethod
  def keep(run: continual.Exp1sSettings, seed: int, outcome: dict) -> None:
    continual.keep_scores(run, seed, outcome)

  @staticmethod
  def save(run, origin: dict, outcomes: list, taken: list[str], wall_time_s: float, results):
    record = continual.assemble_record(run, origin, outcomes, taken, wall_time_s)
    files = saving.save(continual, record, results, ends_command=False)
    continual.finish(record, files)
    return files


class StreamRuns:
  """A continual strategy on a stream: each seed's stages learned once (a build), then scored
  in physics (its evaluation); nothing comes from the zoo."""

  @staticmethod
  def name(run: continual_stream.ContinualSettings) -> str:
    return continual_stream.run_name(run.strategy, run.stream, run.family, run.profile.name)

  @staticmethod
  def unnamed_settings(run: continual_stream.ContinualSettings) -> dict:
    return {"seeds": run.seeds}

  @staticmethod
  def zoo_key(run: continual_stream.ContinualSettings):
    return run

  @staticmethod
  def take_from_zoo(run: continual_stream.ContinualSettings) -> list[str]:
    return []

  @staticmethod
  def resumed_seed(run: continual_stream.ContinualSettings, seed: int) -> dict | None:
    return continual_stream.kept_seed(run, seed)

  @staticmethod
  def seed_build(run: continual_stream.ContinualSettings, seed: int) -> builds.Build:
    configurations = streams.get(run.stream).configurations(run.family)
    home = storage.softbench_home()
    return builds.Build(
      "stages",
      f"stages {StreamRuns.name(run)} seed {seed}",
      (run, seed),
      tuple(path.relative_to(home).as_posix() for path in continual_stream.stage_files(run, seed)),
      tuple(
        builds.dataset_build(configuration.robot, run.profile) for configuration in configurations
      ),
    )

  @staticmethod
  def evaluate(run: continual_stream.ContinualSettings, seed: int) -> dict:
    return continual_stream.run_seed(seed, run)

  @staticmethod
  def keep(run: continual_stream.ContinualSettings, seed: int, outcome: dict) -> None:
    continual_stream.keep_seed(run, seed, outcome)

  @staticmethod
  def save(run, origin: dict, outcomes: list, taken: list[str], wall_time_s: float, results):
    record = continual_stream.assemble_record(run, origin, outcomes, wall_time_s)
    files = saving.save(continual_stream, record, results, ends_command=False)
    continual_stream.finish(run, record, files)
    return files


_KINDS = {
  run_settings.RunSettings: TaskRuns,
  continual.Exp1sSettings: Exp1sRuns,
  continual_stream.ContinualSettings: StreamRuns,
}


def of(run: Setting):
  """The kind of setting ``run`` is."""
  return _KINDS[type(run)]
