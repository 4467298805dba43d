"""What the zoo keeps for a setting: the cache files of a learned agent's seeds (or of Exp1S's
networks), the committed records each of them stands behind, and adding them to the zoo."""

import dataclasses
import pathlib

from softbench import agents
from softbench import continual
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import zoo
from softbench.agents import learned


@dataclasses.dataclass(frozen=True)
class Setting:
  """A learned agent on a robot (``agent`` and ``robot``), or Exp1S on a tendon family
  (``family``), at a profile, for seeds 0 .. seeds-1."""

  profile: profiles.Profile
  seeds: int
  agent: str | None = None
  robot: str | None = None
  family: str | None = None

  @property
  def label(self) -> str:
    return (
      f"smpl {continual.PROTOCOL} on the {self.family} family"
      if self.family
      else f"{self.agent} on {self.robot}"
    ) + f", profile {self.profile.name}"


def setting(
  agent: str | None, robot: str | None, family: str | None, profile: str, seeds: int | None
) -> Setting:
  """A checked ``Setting``: ``agent`` (learned) with ``robot``, or ``family`` alone.

  Raises:
    ValueError: a missing or extra name, an agent that does not learn, an unknown robot, family
      or profile, or seeds < 1 (one line).
  """
  chosen = profiles.get(profile)
  seeds = chosen.seeds if seeds is None else seeds
  if seeds < 1:
    raise ValueError(f"seeds must be at least 1, got {seeds}")
  if family is not None:
    if agent not in (None, "smpl") or robot is not None:
      raise ValueError(
        f"--protocol {continual.PROTOCOL} trains smpl on its family's arms; drop --robot"
      )
    continual.protocol(family)
    return Setting(chosen, seeds, family=family)
  if agent is None or robot is None:
    raise ValueError(
      "name the setting: --agent AGENT --robot ROBOT, or --protocol "
      f"{continual.PROTOCOL} [--family FAMILY]"
    )
  if agents.learner(agent) is None:
    raise ValueError(
      f"the zoo keeps the weights of agents trained on babbling "
      f"({', '.join(agents.babbling_learners())}), not of {agent!r}"
    )
  robots.make(robot)
  return Setting(chosen, seeds, agent=agent, robot=robot)


def requested_setting(
  agent: str | None,
  robot: str | None,
  protocol: str | None,
  family: str | None,
  profile: str,
  seeds: int | None,
) -> Setting:
  """The ``setting`` that ``softbench zoo add`` names: ``agent`` on ``robot``, or ``protocol``
  (Exp1S) on ``family`` (default ``continual.DEFAULT_FAMILY``).

  Raises:
    ValueError: another protocol, a family without the protocol, or what ``setting`` refuses
      (one line).
  """
  if protocol is not None:
    if protocol != continual.PROTOCOL:
      raise ValueError(f"unknown protocol {protocol!r}; the zoo keeps {continual.PROTOCOL}'s")
    family = family or continual.DEFAULT_FAMILY
  elif family is not None:
    raise ValueError(f"--family goes with --protocol {continual.PROTOCOL}")
  return setting(agent, robot, family, profile, seeds)


def cache_files(chosen: Setting) -> list[tuple[int, pathlib.Path, str]]:
  """(seed, cache file, zoo kind) of every file the setting's training writes to the data
  home: each seed's checkpoint, then (for an agent) its forward models."""
  if chosen.family is not None:
    return [
      (seed, continual.checkpoint_path(seed, chosen.profile, chosen.family), "agent")
      for seed in range(chosen.seeds)
    ]
  learner, arm = agents.learner(chosen.agent), robots.make(chosen.robot)
  return [
    (seed, path, kind)
    for seed in range(chosen.seeds)
    for path, kind in learned.cache_files(
      chosen.agent, arm, seed, chosen.profile, learner.per_module
    )
  ]


def stands_behind(record: dict, chosen: Setting, seed: int) -> bool:
  """Whether ``record`` scored seed ``seed`` of ``chosen`` with its weights (healthy robot)."""
  if record["profile"] != chosen.profile.name or seed >= record["seeds"]:
    return False
  if chosen.family is not None:
    return (
      record["format"] == continual.RECORD_FORMAT
      and tuple(record["robots"]) == continual.protocol(chosen.family).robot_names
    )
  return (
    record["format"] == records.FORMAT
    and record["agent"] == chosen.agent
    and record["robot"] == chosen.robot
    and not record.get("faults")
  )


def records_of(chosen: Setting, results: pathlib.Path) -> dict[int, list[str]]:
  """The names of the records in ``results`` that each seed's weights stand behind."""
  found = records.read_folder(results)
  return {
    seed: [path.name for path, record in found if stands_behind(record, chosen, seed)]
    for seed in range(chosen.seeds)
  }


def add(
  chosen: Setting, results: pathlib.Path, zoo_folder: pathlib.Path
) -> tuple[list[zoo.Entry], list[pathlib.Path]]:
  """``zoo.add`` of the setting's cache files, each seed's checkpoint linked to the records in
  ``results`` that it stands behind; returns the entries added and the cache files skipped."""
  linked = records_of(chosen, results)
  files = cache_files(chosen)
  return zoo.add(
    [(path, kind) for _, path, kind in files],
    {path: linked[seed] for seed, path, kind in files if kind == "agent"},
    zoo_folder,
  )
