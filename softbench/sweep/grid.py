"""A sweep's grid and the graph of work behind it, planned in the driver before Ray starts.

Every setting of the grid (robot x task x agent x eval mode, one profile and seed count) is a
``run_settings.RunSettings``; one that already has a record of its profile, seeds and target
completion in the results folder is skipped (``existing_record``), as ``make leaderboard`` skips
it. Each seed of the others is an ``Evaluation``, unless
an interrupted run or sweep kept its episode (``episodes.snapshots``). An evaluation of a learned
agent needs the ``Build`` of that agent for its robot, seed and profile, shared by every task and
eval mode; an agent trained on babbling needs the forward model of each view it reads (shared by
the agents that read that view: the baselines share the whole arm's) and the robot's babbling
dataset, which sac trains on too. A build whose cache files the data home holds already is not
built again: its files are shipped from here.

Exp1S (``--protocol exp1s``, one run per tendon family) fits the same graph: each seed's network
is a build that needs the babbling datasets of the family's arms, and each seed's scores
(``continual.run_seed``) an evaluation of it; the record is the one ``softbench run --protocol
exp1s`` writes.
"""

import dataclasses
import importlib
import itertools
import pathlib

from softbench import agents
from softbench import episodes
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import storage
from softbench import zoo
from softbench.agents import learned
from softbench.agents import learners
from softbench.data import dataset as babbling_dataset
from softbench.learning import checkpoints
from softbench.learning import exp1s as exp1s_training
from softbench.learning import forward_models
from softbench.learning import inverse as inverse_training
from softbench.records import fields as record_fields
from softbench.robots import versions
from softbench.runners import continual
from softbench.runners import run as run_module
from softbench.runners import run_settings

KINDS = ("dataset", "forward", "agent", "network")  # What a build makes (network: Exp1S's).
GridSetting = run_settings.RunSettings | continual.Exp1sSettings  # A task's run, or an Exp1S run.


@dataclasses.dataclass(frozen=True)
class Grid:
  """The settings a sweep covers; ``seeds`` None takes the profile's. ``families``: the tendon
  families to run Exp1S on (``--protocol exp1s``); a sweep of Exp1S alone has no robots, tasks
  or agents."""

  robots: tuple[str, ...]
  tasks: tuple[str, ...]
  agents: tuple[str, ...]
  profile: str = profiles.DEFAULT_PROFILE
  seeds: int | None = None
  eval_modes: tuple[str, ...] = ("physics",)
  families: tuple[str, ...] = ()

  def settings(self) -> list[run_settings.RunSettings]:
    """Every task's setting once, checked (``run_settings.settings``), robot by robot, then task,
    agent, eval mode.

    Raises:
      ValueError: an empty list, or a setting ``run_settings.settings`` refuses (one line).
    """
    if self.families and not (self.robots or self.tasks or self.agents):
      return []  # Exp1S alone.
    for name, values in (
      ("robots", self.robots),
      ("tasks", self.tasks),
      ("agents", self.agents),
      ("eval modes", self.eval_modes),
    ):
      if not values:
        raise ValueError(f"a sweep needs at least one of its {name}")
    every = [
      run_settings.settings(task, agent, robot, self.seeds, self.profile, eval_mode)
      for robot, task, agent, eval_mode in itertools.product(
        self.robots, self.tasks, self.agents, self.eval_modes
      )
    ]
    return list(dict.fromkeys(every))  # A name given twice is one setting.

  def protocol_settings(self) -> list[continual.Exp1sSettings]:
    """The Exp1S run of each family once, checked (``continual.settings``), its seeds resolved.

    Raises:
      ValueError: an unknown family or profile, seeds < 1 (one line).
    """
    return [
      continual.settings(continual.PROTOCOL, "smpl", self.profile, family, self.seeds)
      for family in dict.fromkeys(self.families)
    ]


@dataclasses.dataclass(frozen=True)
class Build:
  """One thing a sweep builds once and shares: a babbling dataset, a forward model or an agent.

  ``arguments`` go to its builder (``tasks.BUILDERS[kind]``); ``files`` are its cache files,
  relative to the data home, in the order they are written (a reader's first look last);
  ``needs`` are the builds it is made from."""

  kind: str
  label: str
  arguments: tuple
  files: tuple[str, ...]
  needs: tuple["Build", ...] = ()


@dataclasses.dataclass(frozen=True)
class Evaluation:
  """One seed's episode of a setting, by the agent that ``agent`` builds (None: built on the
  spot, as an agent that does not learn is); of an Exp1S run, one seed's scores, by the network
  that ``agent`` builds."""

  run: GridSetting
  seed: int
  agent: Build | None

  @property
  def label(self) -> str:
    return f"evaluate {setting_name(self.run)} seed {self.seed}"


@dataclasses.dataclass(frozen=True)
class Plan:
  """What a sweep does: the settings to complete (grid order), the records it skips, the seeds
  resumed from kept episodes, the evaluations to run and the builds they need (each after those
  it needs), those of them the data home holds (shipped, not built), and the zoo files taken for
  each setting's checkpoints (``run.take_from_zoo``)."""

  settings: tuple[GridSetting, ...]
  skipped: tuple[pathlib.Path, ...]
  resumed: dict[tuple[GridSetting, int], tuple[dict, episodes.Episode] | dict]
  evaluations: tuple[Evaluation, ...]
  builds: tuple[Build, ...]
  found: frozenset[Build]
  taken: dict[GridSetting, list[str]]

  def report(self) -> str:
    """What the sweep would do, a line per setting to run, as ``softbench sweep --dry-run``
    prints it."""
    lines = [f"{len(self.settings)} settings to run, {len(self.skipped)} with records skipped"]
    for run in self.settings:
      resumed = sum((run, seed) in self.resumed for seed in range(run.seeds))
      kept = f", {resumed} resumed from kept episodes" if resumed else ""
      lines.append(f"  {setting_name(run)}: {run.seeds - resumed} of {run.seeds} seeds{kept}")
    to_build = [build for build in self.builds if build not in self.found]
    counts = ", ".join(f"{kind} {sum(build.kind == kind for build in to_build)}" for kind in KINDS)
    resuming = sum(resumes(build) for build in to_build)
    lines.append(
      f"to build: {counts} ({resuming} resuming an unfinished training, run first);"
      f" found in the data home: {len(self.found)}"
    )
    return "\n".join(lines)


def setting_name(run: GridSetting) -> str:
  """``agent-robot-task-profile-eval``, as its record's file name begins; of an Exp1S run,
  ``smpl-exp1s-[family-]profile``, as its record's."""
  if isinstance(run, continual.Exp1sSettings):
    return continual.run_name(run.profile.name, run.family)
  return f"{run.agent}-{run.robot}-{run.task}-{run.profile.name}-{run.eval_mode}"


def existing_record(run: GridSetting, results: pathlib.Path) -> pathlib.Path | None:
  """The oldest record of ``run``'s setting in ``results``: a file named ``setting_name``, then a
  date, as ``run.record_path`` (or ``continual.record_path``) names it, that was simulated with
  the installed physics version and holds as many seeds and, for a task, completed partial
  targets the same way (``helpers``; a record without any did not complete them); None if there
  is none.

  Raises:
    records.RecordError: such a file is not a valid, untouched record (one line).
  """
  wanted = _unnamed_settings(run)
  for path in sorted(results.glob(f"{setting_name(run)}-*.json")):
    record = records.read(path)
    same_physics = record_fields.physics_of(record) == versions.current().name
    if same_physics and {field: record.get(field) for field in wanted} == wanted:
      return path
  return None


def _unnamed_settings(run: GridSetting) -> dict:
  """The settings of ``run`` that its record holds but its file name does not say."""
  if isinstance(run, continual.Exp1sSettings):
    return {"seeds": run.seeds}
  return {"seeds": run.seeds, "helpers": run.helpers}


def _relative(path: pathlib.Path) -> str:
  return path.relative_to(storage.softbench_home()).as_posix()


def _dataset_build(robot: str, profile: profiles.Profile) -> Build:
  config = babbling_dataset.generating_config(robot, profile.samples, inverse_training.DATA_SEED)
  folder = babbling_dataset.dataset_folder(config)
  return Build(
    "dataset",
    f"babbling {robot} {profile.samples} samples",
    (robot, profile.samples),
    tuple(  # The manifest last: a reader takes a dataset by its manifest.
      _relative(folder / name) for name in (babbling_dataset.NPZ_NAME, babbling_dataset.JSON_NAME)
    ),
  )


def _forward_builds(
  robot: str, per_module: bool, seed: int, profile: profiles.Profile
) -> tuple[Build, ...]:
  """The forward model of each view an agent reads, each a build of its own."""
  arm = robots.make(robot)
  views = learners.views(arm, per_module)
  configs = forward_models.configs(
    arm,
    views,
    profile.samples,
    inverse_training.DATA_SEED,
    inverse_training.forward_config(seed, profile),
    checkpoints.TRAINING_VERSION,
  )
  return tuple(
    Build(
      "forward",
      f"forward {robot} {view.name} seed {seed}",
      (robot, per_module, index, seed, profile),
      (_relative(forward_models.cache_file(config)),),
      (_dataset_build(robot, profile),),
    )
    for index, (view, config) in enumerate(zip(views, configs))
  )


def agent_build(agent: str, robot: str, seed: int, profile: profiles.Profile) -> Build | None:
  """The build of a learned agent (None for one that does not learn): one trained on babbling
  needs its dataset and forward models, one that learns by acting (sac) the dataset, whose
  targets it trains on. Its files are its checkpoint, where its module says
  (``checkpoint_path``)."""
  entry = agents.describe(agent)
  arm = robots.make(robot)
  dataset = _dataset_build(robot, profile)
  if entry.learner is not None:
    checkpoint = learned.checkpoint_path(agent, arm, seed, profile, entry.learner.per_module)
    needs = (dataset, *_forward_builds(robot, entry.learner.per_module, seed, profile))
  elif entry.learned:
    path = getattr(importlib.import_module(entry.module), "checkpoint_path", None)
    checkpoint, needs = (None if path is None else path(arm, seed, profile)), (dataset,)
  else:
    return None
  files = () if checkpoint is None else (_relative(checkpoint),)
  return Build(
    "agent", f"agent {agent} {robot} seed {seed}", (agent, robot, seed, profile), files, needs
  )


def network_build(run: continual.Exp1sSettings, seed: int) -> Build:
  """The build of an Exp1S seed's network (``continual.build``): it needs the babbling dataset
  of each of the family's arms."""
  arms = dict.fromkeys(arm.name for arm, _ in exp1s_training.protocol(run.family).column_views())
  return Build(
    "network",
    f"network {continual.PROTOCOL} {run.family} seed {seed}",
    (seed, run.profile, run.family),
    (_relative(continual.checkpoint_path(seed, run.profile, run.family)),),
    tuple(_dataset_build(arm, run.profile) for arm in arms),
  )


def is_found(build: Build) -> bool:
  """Whether the data home holds every cache file of ``build`` (one that names none: never)."""
  home = storage.softbench_home()
  return bool(build.files) and all((home / name).is_file() for name in build.files)


UNFINISHED_SUFFIXES = (checkpoints.SNAPSHOT_SUFFIX, ".partial.pt")
"""Where a cache file's unfinished training keeps its state, beside it: ``KEY.partial/`` (a
babbling learner, a forward model; ``smpl.snapshots``) or ``KEY.partial.pt`` (sac)."""


def resumes(build: Build) -> bool:
  """Whether the data home holds the state of an unfinished training of ``build`` itself."""
  home = storage.softbench_home()
  return any(
    (home / name).with_suffix(suffix).exists()
    for name in build.files
    for suffix in UNFINISHED_SUFFIXES
  )


def is_under_way(build: Build) -> bool:
  """Whether ``build`` or a build it needs resumes an unfinished training."""
  return resumes(build) or any(is_under_way(need) for need in build.needs)


def _zoo_key(run: GridSetting) -> tuple:
  """What the checkpoints that ``run`` takes from the zoo depend on (shared by a task's runs)."""
  if isinstance(run, continual.Exp1sSettings):
    return run
  return (run.agent, run.robot, run.profile, run.seeds)


def _take_from_zoo(run: GridSetting) -> list[str]:
  """The zoo files taken for the checkpoints of ``run``'s seeds that the data home lacks."""
  if isinstance(run, continual.Exp1sSettings):
    paths = [continual.checkpoint_path(seed, run.profile, run.family) for seed in range(run.seeds)]
    return zoo.take(paths)[0]
  return run_module.take_from_zoo(run)[0]


def _resumed_seed(run: GridSetting, seed: int) -> tuple[dict, episodes.Episode] | dict | None:
  """What an interrupted run or sweep kept of ``seed``: a task's entry and episode, an Exp1S
  seed's scores; None if nothing."""
  if isinstance(run, continual.Exp1sSettings):
    return continual.kept_scores(run, seed)
  return run_module.resumed_seed(run, seed)


def _seed_build(run: GridSetting, seed: int) -> Build | None:
  """The build that ``seed``'s evaluation of ``run`` needs (None: none)."""
  if isinstance(run, continual.Exp1sSettings):
    return network_build(run, seed)
  return agent_build(run.agent, run.robot, seed, run.profile)


def plan(grid: Grid, results: pathlib.Path) -> Plan:
  """The work of ``grid`` with the records in ``results`` and the data home as they are.

  Raises:
    ValueError: a setting ``Grid.settings`` refuses (one line).
  """
  pending, skipped, resumed, evaluations, taken, taken_by_build = [], [], {}, [], {}, {}
  for run in [*grid.settings(), *grid.protocol_settings()]:
    existing = existing_record(run, results)
    if existing is not None:
      skipped.append(existing)
      continue
    pending.append(run)
    key = _zoo_key(run)
    if key not in taken_by_build:  # Before the checkpoints are looked for.
      taken_by_build[key] = _take_from_zoo(run)
    taken[run] = taken_by_build[key]
    for seed in range(run.seeds):
      outcome = _resumed_seed(run, seed)
      if outcome is not None:
        resumed[run, seed] = outcome
      else:
        evaluations.append(Evaluation(run, seed, _seed_build(run, seed)))
  builds, found = {}, set()

  def add(build: Build) -> None:
    if build in builds:
      return
    if is_found(build):
      found.add(build)
    else:
      for need in build.needs:
        add(need)
    builds[build] = None

  # Work under way first: trainings that resume end before new ones start (Ray starts ready
  # tasks in about the order they were submitted), so fewer unfinished states wait, here or in
  # the zoo.
  agents = [evaluation.agent for evaluation in evaluations if evaluation.agent is not None]
  for agent in sorted(agents, key=lambda build: not is_under_way(build)):
    add(agent)
  return Plan(
    tuple(pending),
    tuple(skipped),
    resumed,
    tuple(evaluations),
    tuple(builds),
    frozenset(found),
    taken,
  )
