"""What the zoo keeps for a setting: the cache files of a learned agent's seeds (or of Exp1S's
networks), the committed records each of them stands behind (those whose ``weights`` section
names these files' sha256), and adding them to the zoo or removing them."""

from collections.abc import Sequence
import dataclasses
import pathlib

from softbench import agents
from softbench import profiles
from softbench import records
from softbench import robots
from softbench import storage
from softbench import zoo
from softbench.agents import learned
from softbench.data import seeding
from softbench.learning import exp1s as exp1s_training
from softbench.records import fields as record_fields
from softbench.robots import versions
from softbench.runners import continual


@dataclasses.dataclass(frozen=True)
class CachedSetting:
  """A learned agent on a robot (``agent`` and ``robot``), or Exp1S on a tendon family
  (``family``), at a profile, for the seeds ``seeds`` (ascending)."""

  profile: profiles.Profile
  seeds: tuple[int, ...]
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
  agent: str | None,
  robot: str | None,
  family: str | None,
  profile: str,
  seeds: int | None,
  only_seeds: Sequence[int] = (),
) -> CachedSetting:
  """A checked ``CachedSetting``: ``agent`` (learned) with ``robot``, or ``family`` alone, for seeds
  0 .. ``seeds``-1 (default: the profile's), or for the seeds ``only_seeds`` alone.

  Raises:
    ValueError: a missing or extra name, an agent that does not learn, an unknown robot, family
      or profile, seeds < 1, a negative seed in ``only_seeds``, or both ``seeds`` and
      ``only_seeds`` (one line).
  """
  chosen = profiles.get(profile)
  seeds = chosen_seeds(chosen, seeds, only_seeds)
  if family is not None:
    if agent not in (None, "smpl") or robot is not None:
      raise ValueError(
        f"--protocol {continual.PROTOCOL} trains smpl on its family's arms; drop --robot"
      )
    exp1s_training.protocol(family)
    return CachedSetting(chosen, seeds, family=family)
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
  return CachedSetting(chosen, seeds, agent=agent, robot=robot)


def chosen_seeds(
  profile: profiles.Profile, seeds: int | None, only_seeds: Sequence[int]
) -> tuple[int, ...]:
  """Seeds 0 .. ``seeds``-1 (default: ``profile``'s number), or ``only_seeds`` (each once,
  ascending), for ``zoo add`` and ``zoo remove``'s ``--seeds N`` and repeatable ``--seed K``.

  Raises:
    ValueError: both given, seeds outside 1 .. ``profiles.MAX_SEEDS`` or a seed outside the
      seed range (``seeding.check_seed``; one line).
  """
  if only_seeds:
    if seeds is not None:
      raise ValueError("--seeds N (seeds 0 .. N-1) and --seed K (seed K alone) exclude each other")
    for seed in only_seeds:
      seeding.check_seed(seed)
    return tuple(sorted(set(only_seeds)))
  return tuple(range(continual.seed_count(profile, seeds)))


def requested_setting(
  agent: str | None,
  robot: str | None,
  protocol: str | None,
  family: str | None,
  profile: str,
  seeds: int | None,
  only_seeds: Sequence[int] = (),
) -> CachedSetting:
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
  return setting(agent, robot, family, profile, seeds, only_seeds)


def cache_files(chosen: CachedSetting) -> list[tuple[int, pathlib.Path, str]]:
  """(seed, cache file, zoo kind) of every file the setting's training writes to the data
  home: each seed's checkpoint, then (for an agent) its forward models."""
  if chosen.family is not None:
    return [
      (seed, continual.checkpoint_path(seed, chosen.profile, chosen.family), "agent")
      for seed in chosen.seeds
    ]
  learner, arm = agents.learner(chosen.agent), robots.make(chosen.robot)
  return [
    (seed, path, kind)
    for seed in chosen.seeds
    for path, kind in learned.cache_files(
      chosen.agent, arm, seed, chosen.profile, learner.per_module
    )
  ]


def stands_behind(record: dict, chosen: CachedSetting, seed: int) -> bool:
  """Whether ``record`` is one of ``chosen``'s with a seed ``seed`` (healthy robot), simulated
  with the installed physics version (the cache files' own)."""
  if record["profile"] != chosen.profile.name or seed >= record["seeds"]:
    return False
  if record_fields.physics_of(record) != versions.current().name:
    return False
  if chosen.family is not None:
    return (
      record["format"] == continual.RECORD_FORMAT
      and tuple(record["robots"]) == exp1s_training.protocol(chosen.family).robot_names
    )
  return (
    record["format"] == records.FORMAT
    and record["agent"] == chosen.agent
    and record["robot"] == chosen.robot
    and not record.get("faults")
  )


def made_by(record: dict, seed: int, hashes: dict[str, str]) -> bool | None:
  """Whether ``record`` scored seed ``seed`` with the weight files of ``hashes`` (data-home path
  -> sha256): every file its ``weights`` section names for the seed has that sha256. None when
  the record names no weights for the seed (made before records named them): it cannot tell."""
  named = [
    entry["files"]
    for entry in record.get(record_fields.WEIGHTS_FIELD, {}).get("per_seed", [])
    if entry["seed"] == seed
  ]
  if not named:
    return None
  return all(hashes.get(path) == sha256 for path, sha256 in named[0].items())


@dataclasses.dataclass(frozen=True)
class Links:
  """The records in a results folder that each seed's weights made (``linked``), and those of
  the setting that name no weights and were not linked (``unchecked``), by file name."""

  linked: dict[int, list[str]]
  unchecked: list[str]


def records_of(chosen: CachedSetting, results: pathlib.Path, link_unchecked: bool = False) -> Links:
  """The records in ``results`` that each seed's weights in the data home made; a record that
  names no weights is linked only with ``link_unchecked``."""
  found = records.read_folder(results)
  files_of_seed: dict[int, list[pathlib.Path]] = {}
  for seed, path, _ in cache_files(chosen):
    files_of_seed.setdefault(seed, []).append(path)
  linked, unchecked = {}, set()
  for seed in chosen.seeds:
    (hashes,) = zoo.weights([files_of_seed[seed]])
    linked[seed] = []
    for path, record in found:
      if not stands_behind(record, chosen, seed):
        continue
      made = made_by(record, seed, hashes)
      if made or (made is None and link_unchecked):
        linked[seed].append(path.name)
      elif made is None:
        unchecked.add(path.name)
  return Links(linked, sorted(unchecked))


def add(
  chosen: CachedSetting,
  results: pathlib.Path,
  zoo_folder: pathlib.Path,
  link_unchecked: bool = False,
) -> tuple[list[zoo.ZooFile], list[pathlib.Path], list[str]]:
  """``zoo.add`` of the setting's cache files, each seed's checkpoint linked to the records in
  ``results`` that its weights made (``records_of``); returns the entries added, the cache files
  skipped and the records not linked because they name no weights."""
  links = records_of(chosen, results, link_unchecked)
  files = cache_files(chosen)
  added, skipped = zoo.add(
    [(path, kind) for _, path, kind in files],
    {path: links.linked[seed] for seed, path, kind in files if kind == "agent"},
    zoo_folder,
  )
  return added, skipped, links.unchecked


def _sharing_forward_models(chosen: CachedSetting) -> list[CachedSetting]:
  """The other settings whose agents may read ``chosen``'s forward models: every other agent
  trained on babbling, on the same robot at the same profile and seeds (none for Exp1S)."""
  if chosen.family is not None:
    return []
  return [
    dataclasses.replace(chosen, agent=other)
    for other in agents.babbling_learners()
    if other != chosen.agent
  ]


def remove(chosen: CachedSetting, zoo_folder: pathlib.Path) -> list[zoo.ZooFile]:
  """``zoo.remove`` of what the zoo holds of the setting: each seed's checkpoint, and the forward
  models that no other agent in the zoo reads; returns the entries removed.

  Raises:
    ValueError: the zoo holds nothing of the setting (one line; nothing is changed).
  """
  entries = zoo.read_manifest(zoo_folder)
  home = storage.softbench_home()

  def held(path: pathlib.Path) -> set[str]:
    return {path.relative_to(home).as_posix()} & set(entries)

  own = cache_files(chosen)
  if not any(held(path) for _, path, kind in own if kind == "agent"):
    raise ValueError(f"the zoo {zoo_folder} holds nothing of {chosen.label}")
  still_read = set()
  for other in _sharing_forward_models(chosen):
    files = cache_files(other)
    in_zoo = {seed for seed, path, kind in files if kind == "agent" and held(path)}
    still_read |= {
      path
      for seed, file, kind in files
      if kind == "forward" and seed in in_zoo
      for path in held(file)
    }
  return zoo.remove({path for _, file, _ in own for path in held(file)} - still_read, zoo_folder)
