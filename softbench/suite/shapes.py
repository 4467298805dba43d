"""The built-in tracking tasks, one function each: the reference the arm traces (``references``).

The planar shapes bend every module alike towards a point moving in the planar actuation space,
in bend amplitudes (one bends the end effector by ``references.BEND_DEG``):

- ``circle``: ``CIRCLE_TURNS`` turns of radius ``CIRCLE_RADIUS``;
- ``rectangle``: ``RECTANGLE_LAPS`` laps of a rectangle of half sides ``RECTANGLE_HALF_SIDES``,
  at constant speed along the perimeter;
- ``spiral``: ``SPIRAL_TURNS`` turns whose radius grows linearly to 1;
- ``babbling``: uniform random actions from a seed stream that motor-babbling datasets never
  use, so the poses are held out from every training set (the paper's "test babbling").

A new one is a function here (or in your own module) under ``suite.tracking_task``; its
parameters are its arguments' defaults, and only they key its cached references.
"""

from typing import TYPE_CHECKING

import numpy as np

from softbench.data import seeding
from softbench.suite.registry import tracking_task

if TYPE_CHECKING:
  from softbench.robots.base import SoftArm

CIRCLE_RADIUS = 0.8  # (bend amplitudes)
CIRCLE_TURNS = 4
RECTANGLE_HALF_SIDES = (0.9, 0.5)  # (bend amplitudes) Along x and y.
RECTANGLE_LAPS = 4
SPIRAL_TURNS = 5
LEAD_IN = 0.05  # Fraction of the steps over which circle and rectangle grow from the centre.
BABBLING_SEED = 0  # Of the held-out babbling stream.


def phases(length: int, cycles: float) -> np.ndarray:
  """Phase in cycles of each control step; step t's target is reached after t + 1 actions."""
  return cycles * np.arange(1, length + 1) / length


def on_circle(radius: np.ndarray | float, phase: np.ndarray) -> np.ndarray:
  """Points (..., 2) at ``radius`` and ``phase`` (cycles) around the origin."""
  angle = 2 * np.pi * phase
  return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=-1)


def grown(length: int, lead_in: float) -> np.ndarray:
  """(length, 1) factors that grow a path from the centre over its first ``lead_in`` steps."""
  return np.minimum(1.0, np.arange(1, length + 1) / (lead_in * length))[:, None]


# The paper runs its Exp2S tracking on the tendon arm (each task's default robot, tendon-3).
@tracking_task("follow held-out poses produced by random actuation", planar=False)
def babbling(
  robot: "SoftArm",
  length: int,
  seed: int = BABBLING_SEED,
  stream: int = seeding.HELD_OUT_BABBLING_STREAM,
) -> np.ndarray:
  """Uniform random actions over the whole action range."""
  return seeding.rng(seed, stream).uniform(-1.0, 1.0, (length, robot.action_dim))


@tracking_task("follow a circle traced in actuation space")
def circle(
  length: int, radius: float = CIRCLE_RADIUS, turns: int = CIRCLE_TURNS, lead_in: float = LEAD_IN
) -> np.ndarray:
  """``turns`` turns of radius ``radius``."""
  return grown(length, lead_in) * on_circle(radius, phases(length, turns))


@tracking_task("follow a rectangle traced in actuation space")
def rectangle(
  length: int,
  half_sides: tuple[float, float] = RECTANGLE_HALF_SIDES,
  laps: int = RECTANGLE_LAPS,
  lead_in: float = LEAD_IN,
) -> np.ndarray:
  """``laps`` laps of the rectangle of ``half_sides``, at constant speed along its perimeter."""
  half_x, half_y = half_sides
  corners = np.array(
    [[half_x, -half_y], [half_x, half_y], [-half_x, half_y], [-half_x, -half_y], [half_x, -half_y]]
  )
  distance = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(corners, axis=0), axis=1))])
  along = (phases(length, laps) % 1.0) * distance[-1]
  path = np.stack(
    [np.interp(along, distance, corners[:, 0]), np.interp(along, distance, corners[:, 1])], axis=-1
  )
  return grown(length, lead_in) * path


@tracking_task("follow a growing spiral traced in actuation space")
def spiral(length: int, turns: int = SPIRAL_TURNS) -> np.ndarray:
  """``turns`` turns whose radius grows linearly from 0 to 1."""
  return on_circle(phases(length, 1.0), phases(length, turns))
