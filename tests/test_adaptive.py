"""Adaptive module activation: the staged procedure on synthetic errors, action masking of learned
agents, the experiment in physics and ``softbench run --adaptive`` (tiny profile)."""

import json

import numpy as np
import pytest

from softbench import agents
from softbench import cli
from softbench import suite
from softbench.agents import learned
from softbench.records import fields
from softbench.runners import evaluation
from softbench.runners.adaptive import experiment
from softbench.runners.adaptive import procedure

ROBOT = "pneumatic-433"  # Three modules of 4, 3 and 3 action entries.
MODULE_ENTRIES = {1: range(0, 4), 2: range(4, 7), 3: range(7, 10)}


@pytest.fixture(autouse=True)
def shared_home(run_wide_home):
  """The run's data home of ROBOT: its agents are trained once (``TestEveryAgent`` of
  test_agents_and_run uses them too)."""
  run_wide_home(ROBOT)


def drive(errors: dict, num_modules: int = 3, target: int = 2, threshold: float = 1.0):
  """Runs the procedure with a fake evaluator: each stage's error looked up by its active set
  (a list of errors is used up in order, for a set that runs twice)."""
  staged = procedure.ActivationProcedure(num_modules, target, threshold)
  while (stage := staged.next_stage()) is not None:
    error = errors[stage.active]
    staged.report(error.pop(0) if isinstance(error, list) else error)
  return staged


def summary(staged: procedure.ActivationProcedure):
  return [(result.stage.kind, result.stage.active, result.kept) for result in staged.results]


class TestProcedure:
  def test_target_alone_then_preceding_then_following(self):
    staged = drive({(2,): 10.0, (1, 2): 6.0, (1, 2, 3): 4.0})
    assert summary(staged) == [
      ("target", (2,), None),
      ("preceding", (1, 2), True),
      ("following", (1, 2, 3), True),
    ]
    assert staged.done and staged.active == (1, 2, 3) and staged.final_error == 4.0

  def test_a_module_that_raises_the_error_is_switched_off_again(self):
    staged = drive({(2,): 10.0, (1, 2): 6.0, (1, 2, 3): 7.0})
    assert summary(staged) == [
      ("target", (2,), None),
      ("preceding", (1, 2), True),
      ("following", (1, 2, 3), False),
      ("revert", (1, 2), None),
    ]
    assert staged.active == (1, 2)
    assert staged.final_error == 6.0  # The revert stage's own error (here the same as before).

  def test_equal_error_is_not_better(self):
    staged = drive({(2,): 10.0, (1, 2): 10.0, (2, 3): 3.0})
    assert summary(staged) == [
      ("target", (2,), None),
      ("preceding", (1, 2), False),
      ("following", (2, 3), True),
    ]
    assert staged.active == (2, 3) and staged.final_error == 3.0

  def test_stops_as_soon_as_the_error_is_within_the_threshold(self):
    assert summary(drive({(2,): 0.5})) == [("target", (2,), None)]
    staged = drive({(2,): 10.0, (1, 2): 0.9})
    assert summary(staged)[-1] == ("preceding", (1, 2), True) and len(staged.results) == 2

  def test_revert_error_is_the_final_error(self):
    staged = drive({(2,): [10.0, 11.5], (1, 2): 12.0, (2, 3): 13.0})
    assert summary(staged)[-1] == ("revert", (2,), None)
    assert staged.active == (2,) and staged.final_error == 11.5

  def test_candidates_go_outwards_preceding_first(self):
    assert procedure.candidates(3, 2) == (1, 3)
    assert procedure.candidates(3, 1) == (2, 3)
    assert procedure.candidates(3, 3) == (2, 1)
    assert procedure.candidates(5, 3) == (2, 4, 1, 5)
    assert procedure.candidates(1, 1) == ()
    assert procedure.ActivationProcedure(3, 2, 1.0).labels == (
      "module 2 alone",
      "+ module 1",
      "+ module 3",
      "back to the kept modules",
    )
    assert procedure.ActivationProcedure(3, 2, 1.0).max_stages == 4

  @pytest.mark.parametrize(
    "arguments,message",
    [
      ((3, 4, 1.0), "target module must be 1 to 3"),
      ((0, 1, 1.0), "num_modules must be"),
      ((3, 2, -1.0), "threshold must be"),
      ((3, 2, float("nan")), "threshold must be"),
    ],
  )
  def test_refuses_bad_settings(self, arguments, message):
    with pytest.raises(ValueError, match=message):
      procedure.ActivationProcedure(*arguments)

  def test_refuses_bad_reports(self):
    staged = procedure.ActivationProcedure(3, 2, 1.0)
    with pytest.raises(ValueError, match="not finished"):
      staged.final_error
    with pytest.raises(ValueError, match="non-negative finite"):
      staged.report(-1.0)
    staged.report(0.0)
    with pytest.raises(ValueError, match="no stage is running"):
      staged.report(1.0)


def reach_actions(agent, active=None, helpers="hold", seed=0):
  acting = agent.with_acting(active_modules=active, helper_targets=helpers)
  env = suite.load(ROBOT, "reach", seed=seed, steps=4)
  return evaluation.run_episode(env, acting, "reach").actions


@pytest.mark.parametrize("agent_name", agents.babbling_learners())
class TestMasking:
  def test_inactive_modules_get_exactly_zero(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    all_on = reach_actions(agent)
    for helpers in fields.HELPER_TARGETS:
      masked = reach_actions(agent, (2,), helpers)
      assert np.all(masked[:, list(MODULE_ENTRIES[1]) + list(MODULE_ENTRIES[3])] == 0.0)
      assert np.all(np.any(masked[:, list(MODULE_ENTRIES[2])] != 0.0, axis=1))
    # The first step's inputs do not depend on the mask (no error, no previous action yet).
    np.testing.assert_array_equal(
      reach_actions(agent, (2,))[0, list(MODULE_ENTRIES[2])], all_on[0, list(MODULE_ENTRIES[2])]
    )

  def test_every_module_active_is_the_unmasked_agent_bit_for_bit(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    for helpers in fields.HELPER_TARGETS:
      np.testing.assert_array_equal(
        reach_actions(agent, (1, 2, 3), helpers), reach_actions(agent, None, helpers)
      )
    np.testing.assert_array_equal(
      reach_actions(agent), reach_actions(agents.make(agent_name, ROBOT, 0, "tiny"))
    )

  def test_refuses_modules_the_robot_lacks(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    with pytest.raises(ValueError, match="active modules must lie in 1 to 3"):
      reach_actions(agent, (2, 4))
    with pytest.raises(ValueError, match="helper_targets must be one of"):
      reach_actions(agent, None, "follow")


def test_helpers_share_the_error_only_with_active_modules():
  agent = agents.make("smpl", ROBOT, 0, "tiny")
  assert not np.array_equal(reach_actions(agent, None, "share"), reach_actions(agent))


def test_experiment_runs_the_procedure_in_one_continuous_episode():
  agent = agents.make("smpl", ROBOT, 0, "tiny")
  stages = experiment.Timing(stage_steps=3, settle_steps=1)
  (outcome,) = experiment.reach_targets(agent, agent.robot, 1, None, stages, threshold=0.0)
  assert [result.stage.active for result in outcome.stages][:2] == [(2,), (1, 2)]
  assert outcome.stages[2].stage.candidate == 3
  assert outcome.stage_ends == tuple(3 * (k + 1) for k in range(len(outcome.stages)))
  assert outcome.path_mm.shape == outcome.all_on_path_mm.shape == (outcome.stage_ends[-1] + 1, 3)
  assert outcome.final_active == outcome.stages[-1].stage.active
  assert outcome.final_error_mm == outcome.stages[-1].error
  np.testing.assert_array_equal(outcome.path_mm[0], outcome.all_on_path_mm[0])  # Same start.
  assert 0 < outcome.effort and 0 < outcome.all_on_effort
  # The first stage's error is the mean distance over its steps after the settle step.
  first = np.linalg.norm(outcome.path_mm[2:4] - outcome.target_mm, axis=1).mean()
  assert outcome.stages[0].error == pytest.approx(first, abs=1e-9)
  assert agent.active_modules is None  # The agent itself is untouched:
  assert agent.helper_targets == learned.DEFAULT_HELPER_TARGETS


def test_softbench_run_adaptive_end_to_end(tmp_path, capsys):
  argv = [
    "run",
    "--task",
    "reach",
    "--agent",
    "smpl",
    "--adaptive",
    "--targets",
    "2",
    "--profile",
    "tiny",
    "--results",
    str(tmp_path),
  ]
  assert cli.main(argv) == 0
  out = capsys.readouterr().out
  for text in (
    "adaptive module activation: smpl (agent seed 0) on reach (pneumatic-433), "
    "module 2, 2 target(s)",
    "module 2 alone",
    "final (adaptive)",
    "all modules on",
    "modules that ended active",
    "whole run",
    "holding the target",
  ):
    assert text in out
  (path,) = tmp_path.glob("*.json")
  assert "-reach-adaptive-tiny-" in path.name
  record = json.loads(path.read_text())
  adaptive = record["adaptive"]
  assert (adaptive["targets"], adaptive["target_module"], adaptive["helpers"]) == (2, 2, "complete")
  assert [target["target_seed"] for target in adaptive["per_target"]] == [0, 1]
  assert sum(adaptive["summary"]["final_active"].values()) == 2
  assert adaptive["summary"]["stages"][0]["stage"] == "module 2 alone"
  assert adaptive["summary"]["stages"][0]["error_mm"]["count"] == 2
  assert len(adaptive["paths"]) == 2
  assert path.with_suffix(".png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
  "argv,message",
  [
    (["--task", "circle", "--agent", "smpl", "--adaptive"], "--adaptive goes with --task reach"),
    (
      ["--task", "reach", "--agent", "smpl", "--adaptive", "--module", "4"],
      "module must be 1 to 3",
    ),
    (
      ["--task", "reach", "--agent", "smpl", "--adaptive", "--targets", "0"],
      "targets must be a positive integer",
    ),
    (["--task", "reach", "--agent", "smpl", "--targets", "3"], "goes with --adaptive"),
    (["--task", "reach", "--agent", "zero", "--adaptive"], "needs an agent trained on babbling"),
    (["--task", "reach", "--agent", "smpl", "--adaptive", "--seeds", "3"], "vary --targets"),
    (["--task", "reach", "--agent", "smpl", "--adaptive", "--helpers", "push"], "unknown helpers"),
    (["--task", "reach", "--agent", "smpl", "--helpers", "push"], "unknown helpers"),
    (["--task", "circle", "--agent", "smpl", "--helpers", "hold"], "gives whole ones"),
    (["--task", "reach", "--agent", "zero", "--helpers", "hold"], "trained on babbling"),
    (["--task", "circle", "--agent", "smpl", "--module", "2"], "--module goes with --task reach"),
    (
      ["--task", "reach", "--agent", "smpl", "--adaptive", "--fault", "2:0:0"],
      "--fault and --adaptive",
    ),
    (
      ["--task", "reach", "--agent", "smpl", "--adaptive", "--video", "reach.mp4"],
      "--adaptive draws its own figure",
    ),
  ],
)
def test_run_adaptive_refuses_bad_input_with_one_line(argv, message, capsys, tmp_path):
  assert cli.main(["run", *argv, "--profile", "tiny", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0]
  assert not list(tmp_path.glob("*"))


@pytest.mark.parametrize("agent_name", agents.babbling_learners())
class TestCompletion:
  """Target completion (``softbench.agents.completion``) in every learned agent."""

  def test_a_reach_goal_is_completed_into_a_whole_arm_target(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    env = suite.load(ROBOT, "reach", seed=1, steps=2)
    first = env.reset().observation
    for helpers in ("complete", "nearest"):
      agent = agent.with_acting(helper_targets=helpers)
      agent.reset(agents.EpisodeInfo("reach", env.task.scored_modules()))
      action = agent.act(first)
      target = agent._previous_target
      assert target.shape == (3, 6) and np.all(np.isfinite(target))
      np.testing.assert_array_equal(target[1, :3], first["target"][0])  # The goal itself.
      np.testing.assert_allclose(np.linalg.norm(target[:, 3:], axis=1), 1.0, atol=1e-6)
      assert np.all(np.abs(action) <= 1.0)

  def test_completion_is_deterministic_and_differs_from_hold(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    completed = reach_actions(agent, None, "complete")
    np.testing.assert_array_equal(completed, reach_actions(agent, None, "complete"))
    np.testing.assert_array_equal(
      completed, reach_actions(agents.make(agent_name, ROBOT, 0, "tiny"), None, "complete")
    )
    assert not np.array_equal(completed, reach_actions(agent, None, "hold"))

  def test_whole_targets_are_used_as_given_bit_for_bit(self, agent_name):
    agent = agents.make(agent_name, ROBOT, 0, "tiny")
    env = lambda: suite.load(ROBOT, "circle", seed=0, length=3)
    runs = []
    for helpers in fields.HELPER_TARGETS:
      acting = agent.with_acting(helper_targets=helpers)
      runs.append(evaluation.run_episode(env(), acting, "circle").actions)
    for actions in runs[1:]:
      np.testing.assert_array_equal(actions, runs[0])
