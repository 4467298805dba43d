"""Properties of the agents that need no training (in the registry: ``zero``, ``random`` and the
model-based ``reference``), on every registered robot.

Episodes are tiny (3 reach steps, the first 10 steps of a 100-step circle) so that the file runs
in well under a minute; the properties do not depend on the length.
"""

import collections
import functools
import os
import pathlib
import platform
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from softbench import agents
from softbench import metrics
from softbench import robots
from softbench import suite
from softbench.agents import reference

UNTRAINED_AGENTS = [name for name in agents.AGENTS if not agents.describe(name).learned]
REACH_STEPS = 3
CIRCLE_LENGTH = 100  # Targets of the circle, of which the tests follow the first ...
TRACKING_STEPS = 10  # ... ones.
BABBLING_LENGTH = 10  # Held-out babbling targets, of which the tests follow the first ...
BABBLING_STEPS = 3  # ... ones (the restart-memory and BLAS test, on BABBLING_ROBOT) ...
BABBLING_SCORED_STEPS = 10  # ... or more (the tracking test; see its comment).
BABBLING_ROBOT = "tendon-local-2"  # Babbles with restarts at a quarter of tendon-3's cost.
FULL_STATE = mujoco.mjtState.mjSTATE_INTEGRATION  # Physics, controls and applied forces.

Episode = collections.namedtuple("Episode", ["actions", "achieved", "targets", "untouched"])


@pytest.fixture(autouse=True)
def shared_cache(tmp_path_factory, monkeypatch):
  """One temporary data home for the whole file, so references are simulated once."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.getbasetemp() / "softbench_home"))


def full_state(physics) -> np.ndarray:
  state = np.empty(mujoco.mj_stateSize(physics.model.ptr, FULL_STATE))
  mujoco.mj_getState(physics.model.ptr, physics.data.ptr, state, FULL_STATE)
  return state


def run_episode(agent: agents.Agent, env, task: str, max_steps: int | None = None) -> Episode:
  """One episode as the evaluation runs it, or its first ``max_steps`` steps: actions
  (T, action_dim), the scored modules' achieved poses (T, scored, 6) and targets
  (T, scored, 6 or 3), and whether every ``act`` left the environment's physics exactly as it
  found it."""
  time_step = env.reset()
  if agent.uses_simulator:
    agent.bind(env.physics)
  scored = env.task.scored_modules()
  agent.reset(agents.EpisodeInfo(task, scored))
  actions, achieved, targets, untouched = [], [], [], True
  while not time_step.last() and len(actions) != max_steps:
    before = full_state(env.physics)
    action = agent.act(time_step.observation)
    untouched &= np.array_equal(full_state(env.physics), before)
    actions.append(np.array(action))
    targets.append(time_step.observation["target"])
    time_step = env.step(action)
    achieved.append(time_step.observation["poses"][np.array(scored) - 1])
  return Episode(np.array(actions), np.array(achieved), np.array(targets), untouched)


@functools.lru_cache(maxsize=None)
def reach_episode(name: str, robot: str, seed: int = 0) -> Episode:
  env = suite.load(robot, "reach", seed=seed, steps=REACH_STEPS)
  return run_episode(agents.make(name, robot, seed), env, "reach")


def tip_error_percent(
  name: str, robot: str, task: str, max_steps: int | None = None, **options
) -> float:
  """Mean normalised tip error (%) of agent ``name`` over (the first ``max_steps`` steps of) an
  episode of ``task``."""
  env = suite.load(robot, task, seed=0, **options)
  episode = run_episode(agents.make(name, robot), env, task, max_steps)
  score = metrics.score(episode.achieved, episode.targets, robots.make(robot).length)
  return score.average("normalised_tip_percent").mean


@pytest.mark.parametrize("name", UNTRAINED_AGENTS)
class TestEveryAgent:
  @pytest.mark.parametrize("robot", robots.REGISTERED_ROBOTS)
  def test_actions_are_finite_in_bounds_and_leave_the_physics(self, name, robot):
    episode = reach_episode(name, robot)
    assert episode.actions.shape == (REACH_STEPS, robots.make(robot).action_dim)
    assert np.all(np.isfinite(episode.actions))
    assert np.all(np.abs(episode.actions) <= 1.0)
    assert episode.untouched  # The agent never changed the environment while acting.

  # Within a family robots differ only in their module count; one robot of each shows a repeat.
  @pytest.mark.parametrize("robot", sorted(family.example for family in robots.FAMILIES))
  def test_actions_are_the_same_for_a_seed(self, name, robot):
    env = suite.load(robot, "reach", seed=0, steps=REACH_STEPS)
    again = run_episode(agents.make(name, robot, 0), env, "reach")
    np.testing.assert_array_equal(again.actions, reach_episode(name, robot).actions)


def test_zero_agent_acts_zeros():
  np.testing.assert_array_equal(reach_episode("zero", "tendon-3").actions, 0.0)


def test_random_agent_repeats_per_episode_and_depends_on_seed():
  agent = agents.make("random", "tendon-2", seed=3)
  env = suite.load("tendon-2", "reach", seed=0, steps=REACH_STEPS)
  first = run_episode(agent, env, "reach").actions
  np.testing.assert_array_equal(run_episode(agent, env, "reach").actions, first)
  other = run_episode(agents.make("random", "tendon-2", seed=4), env, "reach").actions
  assert not np.array_equal(first, other)
  assert len(np.unique(first)) == first.size  # Not a constant action.


def test_reference_agent_needs_the_physics():
  agent = agents.make("reference", "tendon-1")
  assert agent.uses_simulator
  observation = suite.load("tendon-1", "reach", seed=0, steps=1).reset().observation
  with pytest.raises(RuntimeError, match="bind"):
    agent.act(observation)


def test_reference_agent_does_not_depend_on_the_thread_count():
  # Explicit counts: the default is the machine's core count, which may be 1.
  single, several = (
    run_episode(
      reference.ReferenceAgent(robots.make("tendon-3"), 0, threads),
      suite.load("tendon-3", "reach", seed=0, steps=REACH_STEPS),
      "reach",
    )
    for threads in (1, 4)
  )
  np.testing.assert_array_equal(single.actions, several.actions)


@pytest.mark.parametrize(
  "robot,task,options",
  [
    # Measured (mean normalised tip error, zero agent -> reference agent): tendon-2 circle
    # 21.2 % -> 0.0003 %, pneumatic-433 circle 15.6 % -> 0.012 %, tendon-3 reach (module 2)
    # 29.3 % -> 0.002 %. Babbling targets jump across the workspace every step and need the
    # restart from sampled actions: tendon-local-2, first 10 steps, 48.9 % -> 0.010 % (without
    # the restart 8.1 %; tendon-3, 3 to 4 times slower, 50.6 % -> 2.3 %, without it 28.4 %).
    # Scoring fewer steps rests on single steps: on one machine tendon-3's first restart, at
    # step 3, stalled or converged depending on last bits (see the test of OpenBLAS's kernels).
    ("tendon-2", "circle", {"length": CIRCLE_LENGTH, "max_steps": TRACKING_STEPS}),
    (
      "tendon-local-2",
      "babbling",
      {"length": BABBLING_LENGTH, "max_steps": BABBLING_SCORED_STEPS},
    ),
    ("pneumatic-433", "circle", {"length": CIRCLE_LENGTH, "max_steps": TRACKING_STEPS}),
    ("tendon-3", "reach", {"steps": REACH_STEPS}),
  ],
)
def test_reference_agent_tracks_far_better_than_zero(robot, task, options):
  reference = tip_error_percent("reference", robot, task, **options)
  zero = tip_error_percent("zero", robot, task, **options)
  assert reference < zero / 10, (reference, zero)


_BABBLING_ACTIONS_PROGRAM = """
import sys
import numpy as np
import test_agents_model_based as tests
from softbench import agents, suite
agent = agents.make("reference", tests.BABBLING_ROBOT)
for env_seed in map(int, sys.argv[2:]):  # The last episode's actions are saved.
  env = suite.load(tests.BABBLING_ROBOT, "babbling", seed=env_seed, length=tests.BABBLING_LENGTH)
  actions = tests.run_episode(agent, env, "babbling", tests.BABBLING_STEPS).actions
np.save(sys.argv[1], actions)
"""
X86_64 = platform.machine().lower() in ("x86_64", "amd64")


def test_reference_babbling_depends_on_neither_the_blas_kernels_nor_an_earlier_episode(tmp_path):
  """A fresh agent with SSE4.2 kernels (which every x86-64 CPU of the last 15 years has) acts
  as an agent with the machine's own kernels that babbled another episode first.

  numpy's OpenBLAS picks its kernels by CPU; with numpy's algebra, the first babbling restart
  (step 3) stalled 9 to 46 mm off with the AVX-512 kernels, 6 to 31 mm with the SSE ones and
  converged with the AVX2 ones, and step 1's actions already differed by 2e-15 (the kernels are
  the same on an SSE-only CPU or off x86-64, where this checks the episodes alone). Babbling
  restarts at almost every step, from remembered actions after the first restart: the memory
  is the episode's own. On ``BABBLING_ROBOT`` (tendon-3 took 3 to 4 times as long) the three steps
  restart twice, from the sampled actions, then from memory, and numpy's algebra in
  ``reference._damped_least_squares`` makes the two runs differ (by 7e-16; measured)."""

  def babbling_actions(kernel: str | None, env_seeds: list[int]) -> np.ndarray:
    environment = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    environment.pop("OPENBLAS_CORETYPE", None)
    if kernel:
      environment["OPENBLAS_CORETYPE"] = kernel
    environment["PYTHONPATH"] = os.pathsep.join(
      [str(pathlib.Path(__file__).parent), environment.get("PYTHONPATH", "")]
    )
    path = tmp_path / f"{kernel}-{len(env_seeds)}.npy"
    subprocess.run(
      [sys.executable, "-c", _BABBLING_ACTIONS_PROGRAM, str(path), *map(str, env_seeds)],
      check=True,
      env=environment,
      timeout=300,
    )
    return np.load(path)

  fresh = babbling_actions("Nehalem" if X86_64 else None, env_seeds=[0])
  used = babbling_actions(None, env_seeds=[1, 0])
  assert fresh.shape == (BABBLING_STEPS, robots.make(BABBLING_ROBOT).action_dim)
  np.testing.assert_array_equal(fresh, used)
