"""The leaderboard's aggregate across tasks (rliable's way): the IQM of every agent's runs, its
stratified bootstrap interval and performance profiles, checked against the committed records
and against direct computations."""

import pathlib

import numpy as np
import pytest

from softbench import leaderboard
from softbench import records
from softbench.leaderboard import aggregate
from softbench.leaderboard import ranking

RESULTS = pathlib.Path(__file__).resolve().parents[1] / "leaderboard" / "results"
PHYSICS = "v0"  # The committed records of physics v0 are complete and no longer change.


@pytest.fixture(scope="module")
def board():
  return leaderboard.build(RESULTS).of_physics(PHYSICS)


@pytest.fixture(scope="module")
def views(board):
  return aggregate.views(board)


def test_the_iqm_is_the_mean_of_the_middle_half_of_the_runs():
  runs = [np.array([1.0, 2.0, 3.0, 4.0]), np.array([10.0, 20.0, 30.0, 40.0])]
  # Sorted: 1 2 3 4 10 20 30 40; the middle half is 3 4 10 20.
  assert aggregate.iqm(runs) == pytest.approx(np.mean([3.0, 4.0, 10.0, 20.0]))


def test_the_stratified_interval_keeps_each_task_s_share_of_runs():
  # One task's runs all 0, the other's all 1: every stratified resample holds half of each, so
  # its IQM is always 0.5 (an unstratified resample could draw all zeros).
  runs = [np.zeros(5), np.ones(5)]
  assert aggregate.stratified_interval(runs) == (0.5, 0.5)
  spread = [np.array([0.1, 0.2, 0.4, 0.8, 1.6]), np.array([2.0, 2.5, 3.0, 3.5, 4.0])]
  low, high = aggregate.stratified_interval(spread)
  assert low < aggregate.iqm(spread) < high
  assert aggregate.stratified_interval(spread) == (low, high)  # Seeded.


def test_a_performance_profile_rises_from_none_to_every_run():
  runs = [np.array([0.5, 1.0]), np.array([3.0, 30.0])]
  thresholds = np.array([0.1, 0.5, 2.0, 10.0, 50.0])
  np.testing.assert_allclose(
    aggregate.performance_profile(runs, thresholds), [0.0, 0.25, 0.5, 0.75, 1.0]
  )


def test_every_aggregate_is_the_iqm_of_its_records_per_seed_errors(views, board):
  assert views, "the committed records make no aggregate"
  shown = {
    (group.robot, group.task, entry.setting): entry
    for group in board.groups
    if not group.variant
    for entry in group.entries
  }
  for view in views:
    iqms = [found.iqm for found in view.aggregates]
    assert iqms == sorted(iqms)
    for found in view.aggregates:
      per_task = [
        [
          seed[aggregate.METRIC]["mean"]
          for seed in shown[(view.robot, task, (found.agent, view.profile, view.eval_mode))].record[
            "per_seed"
          ]
        ]
        for task in view.tasks
      ]
      ordered = np.sort(np.concatenate(per_task))
      cut = int(aggregate.TRIMMED * len(ordered))  # Whole runs cut from each end.
      assert found.iqm == pytest.approx(np.mean(ordered[cut : len(ordered) - cut]))


def test_the_committed_views_aggregate_every_tracking_task_and_every_agent_has_them(views, board):
  for view in views:
    assert view.tasks == aggregate.tasks() and view.complete == view.aggregates
    for found in view.aggregates:
      tasks = {
        group.task
        for group in board.groups
        if group.robot == view.robot and not group.variant
        for entry in group.entries
        if entry.setting == (found.agent, view.profile, view.eval_mode)
      }
      assert set(view.tasks) <= tasks


def test_an_agent_without_a_record_of_a_new_task_is_shown_with_it_marked(
  views, board, figure_eight, tmp_path
):
  # A task registered after the records were made: one agent has run it, the others are shown
  # as before, the new task named in place of their IQM, ranked after the agent with every task.
  (view,) = [view for view in views if (view.robot, view.profile) == ("tendon-3", "default")]
  folder = tmp_path / "results"
  for group, entry in ranking.plain_entries(board):
    if group.robot == view.robot and entry.setting[1:] == (view.profile, view.eval_mode):
      records.write(entry.record, folder / f"{entry.setting[0]}-{group.task}.json")
      if (entry.setting[0], group.task) == ("smpl", "spiral"):
        records.write({**entry.record, "task": figure_eight}, folder / "smpl-eight.json")
  with_eight = leaderboard.build(folder).of_physics(PHYSICS)
  (shown,) = aggregate.views(with_eight)
  assert shown.tasks == (*view.tasks, figure_eight)
  assert sorted(found.agent for found in shown.aggregates) == sorted(
    found.agent for found in view.aggregates
  )
  assert shown.complete == shown.aggregates[:1] and shown.complete[0].agent == "smpl"
  rows = {row[0]: row for row in shown.table.rows}
  for found in shown.aggregates[1:]:
    assert found.missing == (figure_eight,) and found.iqm is None
    assert rows[found.agent][2:] == (f"- (no {figure_eight})", "-", "-")
  written = leaderboard.write(with_eight, folder, tmp_path)
  assert tmp_path / shown.image in written
  assert f"| zero | 20 | - (no {figure_eight}) | - | - |" in (tmp_path / "README.md").read_text()


def test_a_new_task_nobody_has_run_leaves_the_views_as_they_were(views, board, figure_eight):
  again = aggregate.views(board)
  assert [(view.title, view.tasks, view.table.rows) for view in again] == [
    (view.title, view.tasks, view.table.rows) for view in views
  ]
  assert all(view.table.caption.endswith(f"; no record yet of {figure_eight}") for view in again)


def test_the_pages_show_every_aggregate_and_its_profile_plot(views, board, tmp_path):
  written = leaderboard.write(board, RESULTS, tmp_path)
  page = (tmp_path / "README.md").read_text()
  html = (tmp_path / "index.html").read_text()
  for view in views:
    assert f"## {view.title}" in page and view.image in page and view.anchor in html
    assert (tmp_path / view.image).read_bytes()[:4] == b"\x89PNG"
    assert tmp_path / view.image in written
