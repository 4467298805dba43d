"""What a sweep's Ray tasks run in their worker processes: builds, evaluations and a node's facts.

Each task first sets its process up as ``softbench run``'s seed workers are (one torch thread,
``smpl.fitting.CPU_THREADS``; one-line warnings; its bars relayed to the sweep's display) and
writes the cache files of the builds it is given that its data home lacks (``shipping``). A build
then finds or makes its cached files and returns them; an evaluation returns its seed's record
entry and episode (``run.fresh_seed``), an Exp1S seed's scores (``continual.run_seed``) or a
continual seed's stages and scores (``continual_stream.run_seed``): as ``kinds`` says.
"""

from collections.abc import Iterator
import contextlib

import ray
import torch

from smpl import fitting
from softbench import agents
from softbench import data
from softbench import progress
from softbench import robots
from softbench import terminal
from softbench.agents import learners
from softbench.continual import learning as continual_learning
from softbench.continual import streams
from softbench.episodes import snapshots as episode_snapshots
from softbench.learning import inverse as inverse_training
from softbench.runners import continual
from softbench.sweep import kinds
from softbench.sweep import relay
from softbench.sweep import shipping


@contextlib.contextmanager
def _relayed(states: relay.Relay | None) -> Iterator[None]:
  """The task's process set up as ``parallel_seeds._init_worker`` sets a seed worker up, except
  Ctrl-C, which the driver handles by cancelling: one torch thread, one-line warnings, and the
  task's bars relayed to the driver's ``states`` (None where the sweep shows no progress), all
  sent by the end of the block."""
  torch.set_num_threads(fitting.CPU_THREADS)
  terminal.one_line_warnings()
  progress.relay_to(states)
  try:
    yield
  finally:
    if states is not None:
      states.flush()


def _collect(robot: str, samples: int) -> None:
  """The babbling dataset, simulated on as many threads as the task has cores."""
  cores = int(ray.get_runtime_context().get_assigned_resources().get("CPU", 1))
  data.collect(
    robot, samples=samples, seed=inverse_training.DATA_SEED, workers=cores, progress=False
  )


def _train_forward_model(robot: str, per_module: bool, view: int, seed: int, profile) -> None:
  """The forward model of view ``view`` of the agents with ``per_module`` (``learners.views``)."""
  arm = robots.make(robot)
  inverse_training.trained_forward_models(
    arm, [learners.views(arm, per_module)[view]], seed, profile
  )


def _build_agent(agent: str, robot: str, seed: int, profile) -> None:
  agents.make(agent, robot, seed, profile)


def _train_network(seed: int, profile, family: str) -> None:
  continual.build(seed, profile, False, family)


def _learn_stages(run, seed: int) -> None:
  """Every stage of a continual strategy's seed on its stream (``continual.learning``)."""
  for _ in continual_learning.learn(
    run.strategy, streams.get(run.stream), run.family, seed, run.profile
  ):
    pass


BUILDERS = {
  "dataset": _collect,
  "forward": _train_forward_model,
  "agent": _build_agent,
  "network": _train_network,
  "stages": _learn_stages,
}


def build(
  kind: str,
  arguments: tuple,
  files: tuple[str, ...],
  *needed: shipping.Files,
  states: relay.Relay | None = None,
):
  """Builds (or finds) a ``grid.Build`` of ``kind`` from the builds it needs; its cache files.
  ``states``: where its bars send their states (``_relayed``)."""
  with _relayed(states):
    shipping.write_missing(*needed)
    BUILDERS[kind](*arguments)
  return shipping.read(files)


def evaluate(
  run: kinds.Setting,
  seed: int,
  *needed: shipping.Files,
  states: relay.Relay | None = None,
):
  """Seed ``seed``'s record entry and episode of ``run``, by the agent of ``needed`` if any; of
  an Exp1S run, the seed's scores, by the network of ``needed``. ``states``: as ``build``'s."""
  with _relayed(states):
    shipping.write_missing(*needed)
    return kinds.of(run).evaluate(run, seed)


def node_facts() -> tuple[str, str]:
  """The hash of this node's softbench and smpl source, and the device its agents train on."""
  return episode_snapshots.source_sha256(), str(fitting.default_device())
