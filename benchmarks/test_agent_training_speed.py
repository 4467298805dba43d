"""Closed-loop training speed of every learned agent at the paper's data size, on one CPU thread.

Run with `make bench`. Each case trains an agent's inverse model as `softbench run` does
(`inverse_training.train_inverse`: its committed hyperparameters, views, forward model sizes and the
paper profile's compile setting; only the restart of a diverged training is off, so that every case
times the same epochs) for two epochs on random babbling of the paper's size (14,000 samples in 10
episodes, cut by the real splitter: 9,800 training and 1,400 validation samples per view). The
values are random and the forward models untrained, which changes no operation count. The figure to
read is `extra_info["steady_epoch_s"]`: the second epoch of each model (the first one also
compiles), summed over an SMPL network's columns, i.e. what one epoch of every model costs.
"""

from collections.abc import Iterator
import dataclasses
import pathlib
import time

import numpy as np
import pytest
import torch

from smpl import fitting
from softbench import agents
from softbench import data
from softbench import profiles
from softbench import robots
from softbench.agents import hyperparameters
from softbench.data import dataset as dataset_module
from softbench.learning import inverse as inverse_training

_EPISODES = 10  # The paper profile's 14,000 samples are 10 episodes of 1,400.
_EPOCHS = 2  # Per model: the first compiles (where the profile compiles), the second is steady.
_ROBOTS = ("tendon-3", "pneumatic-433")  # The leaderboard's robots.
_LEARNED_AGENTS = tuple(name for name in agents.AGENTS if agents.describe(name).learned)


@pytest.fixture(autouse=True)
def _training_thread_count() -> Iterator[None]:
  with fitting.limited_cpu_threads(fitting.CPU_THREADS, torch.device("cpu")):
    yield


def _random_babbling(robot: robots.SoftArm, samples: int) -> data.Dataset:
  """A dataset laid out like a collected one, with uniform random actions and poses."""
  generator = np.random.default_rng(0)
  return dataset_module.Dataset(
    path=pathlib.Path("random-babbling"),
    config={"robot": robot.name, "samples": samples},
    actions=generator.uniform(-1, 1, (samples, robot.action_dim)),
    poses=generator.uniform(-0.1, 0.1, (samples + _EPISODES, robot.num_modules, 6)),
    episode_lengths=np.full(_EPISODES, samples // _EPISODES),
    collection={},
  )


@pytest.mark.parametrize("robot_name", _ROBOTS)
@pytest.mark.parametrize("agent", _LEARNED_AGENTS)
def test_closed_loop_training_epoch(benchmark, agent: str, robot_name: str) -> None:
  robot = robots.make(robot_name)
  paper = profiles.get("paper")
  profile = dataclasses.replace(paper, max_epochs=_EPOCHS, patience=_EPOCHS)
  learner = agents.learner(agent)
  views = learner.views(robot)
  babbling = _random_babbling(robot, paper.samples)
  windows = [data.windows(babbling, view) for view in views]
  params = hyperparameters.values(agent, robot.name)
  _, forwards = inverse_training.untrained(views, learner.per_module, learner.make_model, params)
  forwards = [forward.freeze() for forward in forwards]
  epoch_ends: list[float] = []

  def train() -> None:
    epoch_ends.clear()
    epoch_ends.append(time.perf_counter())
    inverse_training.train_inverse(
      views,
      windows,
      forwards,
      seed=0,
      profile=profile,
      per_module=learner.per_module,
      make_model=learner.make_model,
      params=params,
      on_epoch=lambda *_: epoch_ends.append(time.perf_counter()),
      restart_diverged=False,
    )

  benchmark.pedantic(train, rounds=1, iterations=1)
  epoch_s = np.diff(epoch_ends)
  assert len(epoch_s) == _EPOCHS * len(views)
  steady = epoch_s[_EPOCHS - 1 :: _EPOCHS]  # Each model's last epoch.
  benchmark.extra_info["training_windows"] = len(windows[-1].train)
  benchmark.extra_info["epoch_s"] = [round(float(s), 2) for s in epoch_s]
  benchmark.extra_info["steady_epoch_s"] = round(float(steady.sum()), 2)
