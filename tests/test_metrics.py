"""Metrics against hand-computed cases."""

import numpy as np
import pytest

from softbench import metrics


def pose(position, axis):
  return np.concatenate([position, axis]).astype(float)


def test_position_error_is_euclidean_in_mm():
  achieved = pose([0.0, 0.0, -0.1], [0, 0, -1])
  target = pose([0.003, 0.004, -0.1], [0, 0, -1])
  assert metrics.position_error_mm(achieved, target) == pytest.approx(5.0)


def test_orientation_error_is_angle_between_axes_in_degrees():
  x, y = pose([0, 0, 0], [1, 0, 0]), pose([0, 0, 0], [0, 1, 0])
  assert metrics.orientation_error_deg(x, y) == pytest.approx(90.0)
  assert metrics.orientation_error_deg(x, x) == 0.0
  assert metrics.orientation_error_deg(x, pose([0, 0, 0], [-1, 0, 0])) == pytest.approx(180.0)
  # Unnormalised axes count by direction only.
  assert metrics.orientation_error_deg(x, pose([0, 0, 0], [2, 2, 0])) == pytest.approx(45.0)
  # Accurate at tiny angles, where arccos of the dot product loses everything.
  tiny = 1e-7
  turned = pose([0, 0, 0], [np.cos(tiny), np.sin(tiny), 0])
  assert metrics.orientation_error_deg(x, turned) == pytest.approx(np.degrees(tiny), rel=1e-6)


def test_normalised_tip_error_is_percent_of_robot_length():
  achieved = pose([0, 0, -0.15], [0, 0, -1])
  target = pose([0.0015, 0, -0.15], [0, 0, -1])
  assert metrics.normalised_tip_error_percent(achieved, target, 0.15) == pytest.approx(1.0)
  with pytest.raises(ValueError, match="positive"):
    metrics.normalised_tip_error_percent(achieved, target, 0.0)


def test_score_per_module_and_average():
  # Two steps, two modules. Module 1 errs by 1 mm then 3 mm; module 2 by 2 mm both times and
  # is turned by 90 degrees at the second step.
  down = [0, 0, -1]
  target = np.array([[pose([0, 0, -0.05], down), pose([0, 0, -0.1], down)]] * 2)
  achieved = target.copy()
  achieved[0, 0, 0] += 0.001
  achieved[1, 0, 0] += 0.003
  achieved[:, 1, 1] += 0.002
  achieved[1, 1, 3:] = [1, 0, 0]
  score = metrics.score(achieved, target, robot_length=0.1)
  assert score.position_mm[0] == metrics.Statistic(pytest.approx(2.0), pytest.approx(1.0))
  assert score.position_mm[1] == metrics.Statistic(pytest.approx(2.0), pytest.approx(0.0))
  assert score.orientation_deg[1] == metrics.Statistic(pytest.approx(45.0), pytest.approx(45.0))
  assert score.normalised_tip_percent[0].mean == pytest.approx(2.0)
  assert score.average("position_mm") == metrics.Statistic(pytest.approx(2.0), pytest.approx(0.5))
  assert score.average("orientation_deg").mean == pytest.approx(22.5)


def test_position_only_targets():
  achieved = np.array([[pose([0.0, 0.0, -0.1], [0, 0, -1])]])
  target = np.array([[[0.0, 0.006, -0.1 + 0.008]]])
  score = metrics.score(achieved, target, robot_length=0.2)
  assert score.position_mm[0].mean == pytest.approx(10.0)
  assert score.normalised_tip_percent[0].mean == pytest.approx(5.0)
  assert score.orientation_deg == ()
  with pytest.raises(ValueError, match="not measured"):
    score.average("orientation_deg")


def test_statistic_over_seeds():
  statistic = metrics.Statistic.of([1.0, 2.0, 3.0, 4.0])
  assert statistic.mean == pytest.approx(2.5)
  assert statistic.std == pytest.approx(np.sqrt(1.25))
  with pytest.raises(ValueError):
    metrics.Statistic.of([])


def test_bad_shapes():
  with pytest.raises(ValueError, match="3 .* or 6"):
    metrics.position_error_mm(np.zeros(4), np.zeros(4))
  with pytest.raises(ValueError, match="same steps"):
    metrics.score(np.zeros((2, 1, 6)), np.zeros((3, 1, 6)), 0.1)
