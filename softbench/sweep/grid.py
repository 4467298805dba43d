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
exp1s`` writes. So does a continual strategy on a stream (``--protocol continual``): each seed's
stages are a build that needs the datasets of the stream's configurations, and its physics
scores an evaluation (``continual_stream.run_seed``). What differs by kind of setting is
``kinds``'; the builds are ``builds``'.
"""

import dataclasses
import itertools
import pathlib

from softbench import episodes
from softbench import profiles
from softbench import records
from softbench.records import fields as record_fields
from softbench.records.exp1s import DEFAULT_FAMILY
from softbench.robots import versions
from softbench.runners import continual
from softbench.runners import continual_stream
from softbench.runners import run_settings
from softbench.sweep import kinds
from softbench.sweep.builds import KINDS
from softbench.sweep.builds import Build
from softbench.sweep.builds import is_found
from softbench.sweep.builds import is_under_way
from softbench.sweep.builds import resumes

GridSetting = kinds.Setting  # A task's run, an Exp1S run or a continual strategy on a stream.
ContinualSettings = continual_stream.ContinualSettings


@dataclasses.dataclass(frozen=True)
class Grid:
  """The settings a sweep covers; ``seeds`` None takes the profile's. ``families``: the tendon
  families to run Exp1S on (``--protocol exp1s``), or with ``streams``, to run each of
  ``strategies`` on each stream on (``--protocol continual``; default the tendon family); a sweep
  of a protocol alone has no robots, tasks or agents."""

  robots: tuple[str, ...]
  tasks: tuple[str, ...]
  agents: tuple[str, ...]
  profile: str = profiles.DEFAULT_PROFILE
  seeds: int | None = None
  eval_modes: tuple[str, ...] = ("physics",)
  families: tuple[str, ...] = ()
  streams: tuple[str, ...] = ()
  strategies: tuple[str, ...] = ()

  def settings(self) -> list[run_settings.RunSettings]:
    """Every task's setting once, checked (``run_settings.settings``), robot by robot, then task,
    agent, eval mode.

    Raises:
      ValueError: an empty list, or a setting ``run_settings.settings`` refuses (one line).
    """
    if (self.families or self.streams) and not (self.robots or self.tasks or self.agents):
      return []  # A protocol alone.
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

  def protocol_settings(self) -> list[continual.Exp1sSettings | ContinualSettings]:
    """The Exp1S run of each family once, or with ``streams`` each strategy on each stream and
    family (stream by stream), checked (``continual.settings``, ``continual_stream.settings``),
    their seeds resolved.

    Raises:
      ValueError: an unknown family, stream, strategy or profile, a strategy that cannot run a
        stream, streams without strategies, seeds < 1 (one line).
    """
    if not self.streams:
      return [
        continual.settings(continual.PROTOCOL, "smpl", self.profile, family, self.seeds)
        for family in dict.fromkeys(self.families)
      ]
    if not self.strategies:
      raise ValueError("a sweep of streams needs at least one of its strategies (--agents)")
    return [
      continual_stream.settings(strategy, stream, self.profile, family, self.seeds)
      for stream, family, strategy in itertools.product(
        dict.fromkeys(self.streams),
        dict.fromkeys(self.families or (DEFAULT_FAMILY,)),
        dict.fromkeys(self.strategies),
      )
    ]


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
  """How its record's file name begins: ``agent-robot-task-profile-eval`` for a task,
  ``smpl-exp1s-[family-]profile`` for Exp1S, ``strategy-continual-stream-[family-]profile`` for a
  continual run."""
  return kinds.of(run).name(run)


def existing_record(run: GridSetting, results: pathlib.Path) -> pathlib.Path | None:
  """The oldest record of ``run``'s setting in ``results``: a file named ``setting_name``, then a
  date, as ``run.record_path`` (or ``continual.record_path``) names it, that was simulated with
  the installed physics version and holds as many seeds and, for a task, completed partial
  targets the same way (``helpers``; a record without any did not complete them); None if there
  is none.

  Raises:
    records.RecordError: such a file is not a valid, untouched record (one line).
  """
  wanted = kinds.of(run).unnamed_settings(run)
  for path in sorted(results.glob(f"{setting_name(run)}-*.json")):
    record = records.read(path)
    same_physics = record_fields.physics_of(record) == versions.current().name
    if same_physics and {field: record.get(field) for field in wanted} == wanted:
      return path
  return None


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
    kind = kinds.of(run)
    key = kind.zoo_key(run)
    if key not in taken_by_build:  # Before the checkpoints are looked for.
      taken_by_build[key] = kind.take_from_zoo(run)
    taken[run] = taken_by_build[key]
    for seed in range(run.seeds):
      outcome = kind.resumed_seed(run, seed)
      if outcome is not None:
        resumed[run, seed] = outcome
      else:
        evaluations.append(Evaluation(run, seed, kind.seed_build(run, seed)))
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
