"""The ``custom`` task with a trajectory that gives only part of the target (``Given``)."""

import numpy as np
import pytest

from softbench import robots
from softbench import suite
from softbench.agents import zero
from softbench.robots import recorder
from softbench.runners import evaluation
from softbench.suite import tracking
from softbench.suite import trajectories
from softbench.suite.trajectories import Given

SHIFT = 0.05  # Fraction of the arm length by which the second target moves along x.
FIRST_ROBOTS = tuple(family.benchmark[0] for family in robots.FAMILIES)


@pytest.fixture(autouse=True)
def home(tmp_path, monkeypatch):
  monkeypatch.setenv("SOFTBENCH_HOME", str(tmp_path / "home"))


def rest_poses(arm: robots.SoftArm) -> np.ndarray:
  """(num_modules, 6) every module's pose at rest."""
  poses = recorder.PoseRecorder(arm)
  return poses.poses(poses.rest_state())


def whole_rows(arm: robots.SoftArm) -> np.ndarray:
  """(3, num_modules, 6): at rest, moved by SHIFT arm lengths along x, at rest."""
  rest = rest_poses(arm)
  shifted = rest.copy()
  shifted[:, 0] += SHIFT * arm.length
  return np.stack([rest, shifted, rest])


def given_rows(arm: robots.SoftArm, given: Given) -> np.ndarray:
  """(3, len(given.modules) * given.size): the rows of a masked trajectory file."""
  return given.part(whole_rows(arm)).reshape(3, -1)


@pytest.fixture
def tendon_3():
  return robots.make("tendon-3")


class TestGiven:
  @pytest.mark.parametrize(
    "text,modules,orientation",
    [
      ("2", (2,), True),
      ("1,3", (1, 3), True),
      ("3:position", (3,), False),
      ("1,2:position", (1, 2), False),
      (" 1, 3 ", (1, 3), True),
      ("1,2,3", (1, 2, 3), True),
    ],
  )
  def test_parse(self, tendon_3, text, modules, orientation):
    given = Given.parse(text, tendon_3)
    assert (given.modules, given.orientation) == (modules, orientation)
    assert given.size == (6 if orientation else 3)
    assert Given.parse(given.text, tendon_3) == given

  def test_whole_and_text(self, tendon_3):
    assert Given.whole(tendon_3) == Given((1, 2, 3), True)
    assert Given.whole(tendon_3).text == "1,2,3"
    assert Given((1, 3), False).text == "1,3:position"

  @pytest.mark.parametrize(
    "text,message",
    [
      ("", "separated by commas"),
      (":position", "separated by commas"),
      ("two", "separated by commas"),
      ("1,,2", "separated by commas"),
      ("1;2", "separated by commas"),
      ("1 2", "separated by commas"),
      ("-1", "separated by commas"),
      ("2:orientation", "separated by commas"),
      ("2:Position", "separated by commas"),
      ("2:position:position", "separated by commas"),
      ("0", "not a module of tendon-3"),
      ("4", r"not a module of tendon-3 \(1 to 3\)"),
      ("1,4:position", "given module 4"),
      ("2,2", "must not repeat"),
      ("3,1", "ascending order"),
      (2, "must be text"),
    ],
  )
  def test_malformed_text(self, tendon_3, text, message):
    with pytest.raises(ValueError, match=message) as error:
      Given.parse(text, tendon_3)
    assert "\n" not in str(error.value)

  @pytest.mark.parametrize(
    "modules,orientation,message",
    [
      ((), True, "non-empty"),
      ([1], True, "non-empty tuple"),
      ((0,), True, "1-based"),
      ((1, 1), True, "repeat"),
      ((2, 1), True, "ascending"),
      ((1,), "yes", "True or False"),
    ],
  )
  def test_malformed_fields(self, modules, orientation, message):
    with pytest.raises(ValueError, match=message):
      Given(modules, orientation)

  def test_part(self, tendon_3):
    poses = np.arange(2 * 3 * 6, dtype=float).reshape(2, 3, 6)
    np.testing.assert_array_equal(Given((1, 3), False).part(poses), poses[:, [0, 2], :3])
    np.testing.assert_array_equal(Given.whole(tendon_3).part(poses), poses)


class TestLoading:
  @pytest.mark.parametrize("text", ["2", "1,3", "3:position", "1,2:position"])
  @pytest.mark.parametrize("suffix", [".npy", ".csv"])
  def test_files_hold_only_the_given_columns(self, tendon_3, tmp_path, text, suffix):
    given = Given.parse(text, tendon_3)
    rows = given_rows(tendon_3, given)
    path = tmp_path / f"trajectory{suffix}"
    if suffix == ".npy":
      np.save(path, rows)
    else:
      np.savetxt(path, rows, delimiter=",")
    targets = trajectories.load_trajectory(path, tendon_3, given)
    assert targets.shape == (3, len(given.modules), given.size)
    np.testing.assert_allclose(targets, given.part(whole_rows(tendon_3)), atol=1e-15)
    # Text works as well as a Given, and (steps, modules, size) arrays as well as rows.
    from_array = trajectories.load_trajectory(targets, tendon_3, text)
    np.testing.assert_array_equal(from_array, targets)

  def test_without_given_the_whole_pose_of_every_module(self, tendon_3):
    rows = whole_rows(tendon_3)
    np.testing.assert_array_equal(trajectories.load_trajectory(rows, tendon_3), rows)
    with pytest.raises(ValueError, match=r"\(steps, 18\)"):
      trajectories.load_trajectory(given_rows(tendon_3, Given((2,))), tendon_3)

  @pytest.mark.parametrize(
    "text,columns,expected",
    [
      ("1,3", 6, r"\(steps, 12\).*orientation vector of given module\(s\) 1,3"),
      ("1,3", 18, r"\(steps, 12\)"),
      ("2:position", 6, r"\(steps, 3\): per row, the tip position \(m\) of given module\(s\) 2;"),
      ("1,2:position", 3, r"\(steps, 6\)"),
    ],
  )
  def test_wrong_column_count_names_the_expected_shape(self, tendon_3, text, columns, expected):
    rows = np.zeros((3, columns))
    with pytest.raises(ValueError, match=expected):
      trajectories.load_trajectory(rows, tendon_3, text)

  def test_wrong_column_count_in_a_csv_file(self, tendon_3, tmp_path):
    path = tmp_path / "trajectory.csv"
    np.savetxt(path, given_rows(tendon_3, Given.whole(tendon_3)), delimiter=",")
    with pytest.raises(ValueError, match=r"\(steps, 3\)"):
      trajectories.load_trajectory(path, tendon_3, "2:position")

  @pytest.mark.parametrize("text", ["2", "1,3:position"])
  def test_nan_and_no_rows_are_errors(self, tendon_3, text):
    rows = given_rows(tendon_3, Given.parse(text, tendon_3))
    rows[1, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
      trajectories.load_trajectory(rows, tendon_3, text)
    with pytest.raises(ValueError, match="no rows"):
      trajectories.load_trajectory(rows[:0], tendon_3, text)

  def test_far_positions_are_refused(self, tendon_3):
    rows = given_rows(tendon_3, Given((3,), False))
    rows[2, 0] = 1e300
    with pytest.raises(ValueError, match="row 2: .*arm lengths"):
      trajectories.load_trajectory(rows, tendon_3, "3:position")

  def test_unit_orientation_checked_only_where_given(self, tendon_3):
    rows = given_rows(tendon_3, Given((1, 3)))
    rows[1, 9:12] *= 2  # Module 3's orientation vector.
    with pytest.raises(ValueError, match="row 1: orientation vectors must have unit length"):
      trajectories.load_trajectory(rows, tendon_3, "1,3")
    # Positions only: columns 3-5 are module 2's position, not an orientation vector.
    rows = given_rows(tendon_3, Given((1, 2), False))
    assert not np.allclose(np.linalg.norm(rows[:, 3:6], axis=-1), 1.0)
    assert trajectories.load_trajectory(rows, tendon_3, "1,2:position").shape == (3, 2, 3)

  @pytest.mark.parametrize(
    "given,message",
    [("4", "given module 4"), ("2:pose", "separated by commas"), (2, "must be None, a Given")],
  )
  def test_bad_given_through_load(self, given, message):
    rows = np.zeros((2, 3))
    with pytest.raises(ValueError, match=message):
      suite.load("tendon-3", "custom", trajectory=rows, given=given)
    with pytest.raises(ValueError, match="given module 4"):
      suite.load("tendon-3", "custom", trajectory=rows, given=Given((4,), False))


def test_tracking_checks_targets_against_given(tendon_3):
  task = tracking.Tracking(tendon_3, np.zeros((2, 2, 3)), given=Given((1, 3), False))
  assert (task.target_size, task.scored_modules()) == (3, (1, 3))
  assert tracking.Tracking(tendon_3, whole_rows(tendon_3)).target_size == 6
  with pytest.raises(ValueError, match=r"targets must be \(steps, 2, 3\)"):
    tracking.Tracking(tendon_3, np.zeros((2, 2, 6)), given=Given((1, 3), False))


def _masks(robot: str) -> list[str]:
  modules = robots.make(robot).num_modules
  return [f"{modules}:position", "1"]


@pytest.mark.parametrize(
  "robot,text",
  [(robot, text) for robot in FIRST_ROBOTS for text in _masks(robot)] + [("tendon-3", "1,3")],
)
def test_masked_custom_episode(robot, text):
  arm = robots.make(robot)
  given = Given.parse(text, arm)
  env = suite.load(
    arm, "custom", trajectory=given_rows(arm, given), given=text, initial_actuation=0.0
  )
  assert env.task.scored_modules() == given.modules
  assert env.observation_spec()["target"].shape == (len(given.modules), given.size)
  assert env.reset().observation["target"].shape == (len(given.modules), given.size)

  episode = evaluation.run_episode(env, zero.ZeroAgent(arm, 0), "custom")
  assert episode.scored_modules == given.modules
  assert episode.targets.shape == (3, len(given.modules), given.size)
  assert np.all((episode.rewards >= 0.0) & (episode.rewards <= 1.0))
  assert episode.rewards[1] < episode.rewards[0]  # The second target lies SHIFT away.
  score = episode.score(arm.length)
  assert len(score.position_mm) == len(score.normalised_tip_percent) == len(given.modules)
  assert len(score.orientation_deg) == (len(given.modules) if given.orientation else 0)
  # The zero action holds the arm near rest: the error is that of the shifted target, 1 of 3 steps.
  shifted_mm = SHIFT * arm.length * 1000
  for position in score.position_mm:
    assert position.mean == pytest.approx(shifted_mm / 3, rel=0.25)


@pytest.mark.parametrize("task", [task for task in suite.TASKS if task != "custom"])
def test_every_task_says_whether_its_targets_are_whole_as_its_episodes_show(task):
  arm = robots.make("tendon-2")
  env = suite.load(arm, task, **suite.length_options(task, 1))
  target = env.reset().observation["target"]
  shown_whole = target.shape == (arm.num_modules, 6)
  assert suite.gives_whole_targets(arm, task, **suite.length_options(task, 1)) == shown_whole


@pytest.mark.parametrize(
  "text,whole", [(None, True), ("1,2", True), ("2", False), ("1,2:position", False)]
)
def test_a_custom_trajectory_is_whole_only_if_it_gives_every_modules_pose(text, whole):
  arm = robots.make("tendon-2")
  given = Given.whole(arm) if text is None else Given.parse(text, arm)
  options = {"trajectory": given_rows(arm, given), **({} if text is None else {"given": text})}
  assert suite.gives_whole_targets(arm, "custom", **options) == whole
  assert (suite.load(arm, "custom", **options).task.target_size == 6) == (given.orientation)
