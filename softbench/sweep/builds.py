"""The builds of a sweep's graph: what it makes once and shares (a babbling dataset, a forward
model, an agent, Exp1S's network, a continual strategy's stages), each named by its cache files,
and whether the data home holds them or an unfinished training of them."""

import dataclasses
import importlib
import pathlib

from softbench import agents
from softbench import profiles
from softbench import robots
from softbench import storage
from softbench.agents import learned
from softbench.agents import learners
from softbench.data import dataset as babbling_dataset
from softbench.learning import checkpoints
from softbench.learning import exp1s as exp1s_training
from softbench.learning import forward_models
from softbench.learning import inverse as inverse_training
from softbench.runners import continual

KINDS = ("dataset", "forward", "agent", "network", "stages")
"""What a build makes (network: an Exp1S seed's; stages: a continual strategy's, one seed)."""


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


def _relative(path: pathlib.Path) -> str:
  return path.relative_to(storage.softbench_home()).as_posix()


def dataset_build(robot: str | robots.SoftArm, profile: profiles.Profile) -> Build:
  """The babbling dataset of ``robot`` (a registered name, or an arm with faults or a payload)."""
  arm = robots.make(robot) if isinstance(robot, str) else robot
  plain = arm == robots.make(arm.name)
  variant = "".join(
    [f" fault {fault}" for fault in arm.faults]
    + ([f" payload {arm.payload * 1000:g} g"] if arm.payload else [])
  )
  config = babbling_dataset.generating_config(arm, profile.samples, inverse_training.DATA_SEED)
  folder = babbling_dataset.dataset_folder(config)
  return Build(
    "dataset",
    f"babbling {arm.name}{variant} {profile.samples} samples",
    (arm.name if plain else arm, profile.samples),
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
      (dataset_build(robot, profile),),
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
  dataset = dataset_build(robot, profile)
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
    tuple(dataset_build(arm, run.profile) for arm in arms),
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
