"""``ArmBatch`` (``softbench.robots.batch``): many arms of one robot stepped at once, against the
serial path (``SoftArmPhysics``: ``set_action`` then ``step``, one arm at a time), on every
registered robot: bit for bit on the ``cpu`` backend, within ``PARITY_TOLERANCE_M`` on ``warp``
(run on Warp's CPU device here; skipped, with the reason, where MuJoCo Warp is not installed).
"""

import re

import numpy as np
import pytest

from softbench import robots
from softbench.robots import batch
from softbench.robots import batch_warp
from softbench.robots import physics as arm_physics
from softbench.robots import versions

pytestmark = pytest.mark.skipif(
  versions.current().name == versions.FIRST, reason="ArmBatch needs MuJoCo 4's mujoco.batch"
)

ARMS = 3
PERIODS = 2


def actions(arm: robots.SoftArm, seed: int = 0) -> np.ndarray:
  """(PERIODS, ARMS, action_dim) random actions in [-1, 1]."""
  return np.random.default_rng(seed).uniform(-1.0, 1.0, (PERIODS, ARMS, arm.action_dim))


def serial_poses(arm: robots.SoftArm, held: np.ndarray) -> np.ndarray:
  """(PERIODS, ARMS, num_modules, 6): each arm alone on the serial path, from rest."""
  poses = np.empty((PERIODS, ARMS, arm.num_modules, batch.POSE_SIZE))
  steps = int(round(arm.control_timestep / arm.compile().opt.timestep))
  for index in range(ARMS):
    physics = arm_physics.SoftArmPhysics.from_robot(arm)
    for period in range(PERIODS):
      physics.set_action(held[period, index])
      physics.step(steps)
      poses[period, index] = physics.module_poses()
  return poses


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_the_cpu_backend_steps_every_robot_bit_for_bit_as_the_serial_path(name):
  arm = robots.make(name)
  held = actions(arm)
  with batch.make(arm, ARMS, backend="cpu", threads=2) as arms:
    stepped = []
    for period in range(PERIODS):
      arms.hold(held[period])
      stepped.append(arms.poses())
  np.testing.assert_array_equal(np.stack(stepped), serial_poses(arm, held))


def test_arms_left_out_keep_their_state_and_reset_arms_return_to_rest():
  arm = robots.make("tendon-1")
  held = actions(arm)
  with batch.CpuArmBatch(arm, ARMS, threads=2) as arms:
    rest = arms.poses()
    arms.hold(held[0])
    before = arms.poses()
    arms.hold(held[1][[0, 2]], arms=[0, 2])
    np.testing.assert_array_equal(arms.poses([1]), before[[1]])
    arms.reset([2])
    np.testing.assert_array_equal(arms.poses([2]), rest[[2]])
    states = arms.states([0])
    arms.set_states(states, [1])
    np.testing.assert_array_equal(arms.poses([1]), arms.poses([0]))


@pytest.mark.parametrize(
  "call, message",
  [
    (lambda arms: arms.hold(np.zeros((3, 1))), "actions must have shape"),
    (lambda arms: arms.hold(np.full((3, 2), 2.0)), "lie in [-1, 1]"),
    (lambda arms: arms.hold(np.full((3, 2), np.nan)), "finite"),
    (lambda arms: arms.hold(np.zeros((1, 2)), arms=[3]), "must lie in [0, 3)"),
    (lambda arms: arms.hold(np.zeros((2, 2)), arms=[1, 1]), "distinct"),
    (lambda arms: arms.poses([0.5]), "integer indices"),
  ],
)
def test_bad_actions_and_arms_get_one_line_errors(call, message):
  """On tendon-1 (2 action entries)."""
  with batch.CpuArmBatch(robots.make("tendon-1"), 3, threads=1) as arms:
    with pytest.raises(ValueError, match=re.escape(message)) as error:
      call(arms)
  assert "\n" not in str(error.value)


@pytest.mark.parametrize(
  "kwargs, message",
  [({"num_arms": 0}, "positive integer"), ({"backend": "jax"}, "backend must be one of")],
)
def test_bad_batch_arguments_get_one_line_errors(kwargs, message):
  with pytest.raises(ValueError, match=message):
    batch.make(robots.make("tendon-1"), **{"num_arms": 2, **kwargs})


@pytest.mark.skipif(
  not batch_warp.installed(), reason="MuJoCo Warp is not installed (make install-gpu)"
)
@pytest.mark.parametrize("name", ["tendon-1", "pneumatic-433"])
def test_the_warp_backend_stays_within_its_tolerance_of_the_serial_path(name):
  arm = robots.make(name)
  held = actions(arm)
  arms = batch_warp.WarpArmBatch(arm, ARMS, device="cpu")
  arms.hold(held[0])
  serial = serial_poses(arm, held)[0]
  assert np.abs(arms.poses()[..., :3] - serial[..., :3]).max() < batch_warp.PARITY_TOLERANCE_M
