"""Reference trajectories that the robot can follow, because the robot itself traced them.

Each reference drives the simulated arm from rest with an actuation pattern and records every
module's pose after each control period (``PoseRecorder``). The patterns bend every module alike
towards a point moving in the planar actuation space of ``SoftArm.planar_action``:

- ``circle``: ``CIRCLE_TURNS`` turns of radius ``CIRCLE_RADIUS``;
- ``rectangle``: ``RECTANGLE_LAPS`` laps of a rectangle of half sides ``RECTANGLE_HALF_SIDES``,
  at constant speed along the perimeter;
- ``spiral``: ``SPIRAL_TURNS`` turns whose radius grows linearly to ``SPIRAL_MAX_RADIUS``;
- ``babbling``: uniform random actions from a seed stream that motor-babbling datasets never
  use, so the poses are held out from every training set (the paper's "test babbling").

References are cached under ``softbench_home()/references``, keyed by a hash of everything that
generates them (the robot's MJCF included), with a content hash checked on every load; a damaged
one is reported (``CorruptFileWarning``) and generated again. Processes sharing a data home
generate each reference once: the others wait for it (``storage.found_or_made``). The generating
actions are stored for replay checks; tasks show controllers only the poses.
"""

from collections.abc import Callable
import dataclasses
import functools
import hashlib
import json
import os
import pathlib
import sys

import numpy as np
from rich import console

from softbench import progress
from softbench import storage
from softbench.data import dataset
from softbench.data import seeding
from softbench.robots import base
from softbench.robots import recorder

REFERENCE_LENGTH = 1000  # Target poses per reference (paper: 1,000 samples per trajectory).
BEND_DEG = 60.0  # (deg) End-effector bend at one bend amplitude.
CIRCLE_RADIUS = 0.8  # Bend amplitudes.
CIRCLE_TURNS = 4
RECTANGLE_HALF_SIDES = (0.9, 0.5)  # Bend amplitudes along x and y.
RECTANGLE_LAPS = 4
SPIRAL_TURNS = 5
LEAD_IN = 0.05  # Fraction of the steps over which circle and rectangle grow from the centre.
AMPLITUDE_GRID = np.linspace(0.05, 1.0, 20)  # Actuations tried when calibrating the amplitude.
SETTLE_SECONDS = 3.0  # (s) Hold per calibration actuation; longer than any settling time.
FORMAT_VERSION = 1
FOLDER = "references"  # In the data home.


def _phases(length: int, cycles: float) -> np.ndarray:
  """Phase in cycles of each control step; step t's target is reached after t + 1 actions."""
  return cycles * np.arange(1, length + 1) / length


def _on_circle(radius: np.ndarray | float, phase: np.ndarray) -> np.ndarray:
  angle = 2 * np.pi * phase
  return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=-1)


def _on_rectangle(phase: np.ndarray) -> np.ndarray:
  half_x, half_y = RECTANGLE_HALF_SIDES
  corners = np.array(
    [[half_x, -half_y], [half_x, half_y], [-half_x, half_y], [-half_x, -half_y], [half_x, -half_y]]
  )
  distance = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(corners, axis=0), axis=1))])
  along = (phase % 1.0) * distance[-1]
  return np.stack(
    [np.interp(along, distance, corners[:, 0]), np.interp(along, distance, corners[:, 1])], axis=-1
  )


@functools.lru_cache(maxsize=None)
def bend_amplitude(robot: base.SoftArm) -> float:
  """The planar actuation (fraction of full) that bends the end effector by ``BEND_DEG`` at
  equilibrium, interpolated on ``AMPLITUDE_GRID`` below the first grid point that reaches it.

  The grid is held in ascending batches of one actuation per core, up to the batch that reaches
  ``BEND_DEG``: the answer of holding the whole grid (each actuation is simulated on its own),
  holding 25 to 70 % of its actuations on the registered robots (the most on one-module arms)."""
  holds = int(np.ceil(SETTLE_SECONDS / robot.control_timestep))
  batch = os.cpu_count() or 1
  pose_recorder = recorder.PoseRecorder(robot, workers=batch)
  rest_axis = pose_recorder.poses(pose_recorder.rest_state())[-1, 3:]
  held = []
  for start in range(0, len(AMPLITUDE_GRID), batch):
    amplitudes = AMPLITUDE_GRID[start : start + batch]
    points = np.stack([amplitudes, np.zeros_like(amplitudes)], axis=-1)
    actions = np.repeat(robot.planar_action(points)[:, None], holds, axis=1)
    poses, _ = pose_recorder.record(actions)
    held.extend(np.degrees(np.arccos(np.clip(poses[:, -1, -1, 3:] @ rest_axis, -1.0, 1.0))))
    if max(held[start:]) >= BEND_DEG:
      break
  bends = np.array(held)
  reached = np.flatnonzero(bends >= BEND_DEG)
  if len(reached) == 0:
    return 1.0
  first = reached[0]
  if first == 0:
    return float(AMPLITUDE_GRID[0])
  return float(
    np.interp(BEND_DEG, bends[first - 1 : first + 1], AMPLITUDE_GRID[first - 1 : first + 1])
  )


def _lead_in(length: int) -> np.ndarray:
  """(length, 1) factors that grow a path from the centre over its first ``LEAD_IN`` steps."""
  return np.minimum(1.0, np.arange(1, length + 1) / (LEAD_IN * length))[:, None]


def _circle(length: int) -> np.ndarray:
  return _lead_in(length) * _on_circle(CIRCLE_RADIUS, _phases(length, CIRCLE_TURNS))


def _rectangle(length: int) -> np.ndarray:
  return _lead_in(length) * _on_rectangle(_phases(length, RECTANGLE_LAPS))


def _spiral(length: int) -> np.ndarray:
  return _on_circle(_phases(length, 1.0), _phases(length, SPIRAL_TURNS))


def _planar(path: Callable[[int], np.ndarray]) -> Callable[..., np.ndarray]:
  """The actions of a path (length, 2) in the planar actuation space, in bend amplitudes."""

  def actions(robot: base.SoftArm, length: int, amplitude: float | None) -> np.ndarray:
    amplitude = bend_amplitude(robot) if amplitude is None else amplitude
    return robot.planar_action(amplitude * path(length))

  return actions


def _babbling(robot: base.SoftArm, length: int, amplitude: float | None) -> np.ndarray:
  del amplitude  # Uniform over the whole action range.
  stream = seeding.rng(0, seeding.HELD_OUT_BABBLING_STREAM)
  return stream.uniform(-1.0, 1.0, (length, robot.action_dim))


_GENERATORS = {
  "babbling": _babbling,
  "circle": _planar(_circle),
  "rectangle": _planar(_rectangle),
  "spiral": _planar(_spiral),
}
"""Shape name -> ``generate(robot, length, amplitude) -> actions (length, action_dim)``; a new
shape is a generator and one entry here."""
SHAPES = tuple(_GENERATORS)


def _check_shape(shape: str) -> None:
  if shape not in _GENERATORS:
    raise ValueError(f"unknown reference shape {shape!r}; choose one of {', '.join(SHAPES)}")


def pattern_actions(
  robot: base.SoftArm, shape: str, length: int = REFERENCE_LENGTH, amplitude: float | None = None
) -> np.ndarray:
  """The generating actions (length, action_dim) of reference ``shape``; ``amplitude`` is
  ``bend_amplitude(robot)`` unless given."""
  _check_shape(shape)
  return _GENERATORS[shape](robot, length, amplitude)


@dataclasses.dataclass(frozen=True)
class Reference:
  """A recorded reference: ``poses[0]`` is the rest pose, ``poses[t + 1]`` the pose reached by
  holding ``actions[t]``."""

  shape: str
  actions: np.ndarray  # (length, action_dim)
  poses: np.ndarray  # (length + 1, num_modules, 6)

  @property
  def targets(self) -> np.ndarray:
    """(length, num_modules, 6): the pose to reach at each control step."""
    return self.poses[1:]


def _config(robot: base.SoftArm, shape: str, length: int) -> dict:
  return {
    "format": FORMAT_VERSION,
    "robot": robot.name,
    "shape": shape,
    "length": length,
    "robot_xml_sha256": robot.physics_sha256(),
    "bend_deg": BEND_DEG,
    "amplitude_grid": AMPLITUDE_GRID.tolist(),
    "lead_in": LEAD_IN,
    "circle": [CIRCLE_RADIUS, CIRCLE_TURNS],
    "rectangle": [*RECTANGLE_HALF_SIDES, RECTANGLE_LAPS],
    "spiral": [SPIRAL_TURNS],
  }


def _load_cached(path, config: dict) -> Reference | None:
  """The cached reference at ``path`` if it is intact and made with ``config``; None if absent,
  or, damaged, with a ``CorruptFileWarning`` (``storage.read_cached``; it is generated again)."""
  meta_path = path.with_suffix(".json")
  if not meta_path.exists():
    return None

  def read(npz_path) -> Reference:
    try:
      meta = json.loads(meta_path.read_text())
    except Exception as error:  # Named, since the warning names the arrays' file.
      raise ValueError(f"{meta_path}: {dataset.first_line(error)}") from None
    if not isinstance(meta, dict):
      raise ValueError(f"{meta_path} is not a JSON object")
    stored = dataset.read_npz(npz_path.read_bytes(), ValueError)
    arrays = {"actions": stored["actions"], "poses": stored["poses"]}
    if meta.get("config") != config or meta.get("sha256") != storage.arrays_sha256(arrays):
      raise ValueError("content does not match its hash")
    return Reference(config["shape"], arrays["actions"], arrays["poses"])

  return storage.read_cached(path, read, "cached reference", "generating it again", (meta_path,))


def _simulate(robot: base.SoftArm, shape: str, length: int) -> tuple[np.ndarray, np.ndarray]:
  """The actions of reference ``shape`` and the poses they give, simulated from rest, saying so
  on stderr: a line, then a bar of the control steps (7 to 36 s on tendon-1..3 and up to 132 s on
  tendon-5's babbling, once per data home; the planar shapes' calibration, up to 5 s, first)."""
  print(
    f"simulating {robot.name}'s {shape} reference ({length} control steps; once, then cached in "
    f"the data home)",
    file=sys.stderr,
    flush=True,
  )
  display = progress.counting(
    extra=progress.time_left(), transient=True, console=console.Console(stderr=True)
  )
  with display:
    bar = display.add_task(f"{robot.name} {shape} reference", total=length)
    actions = pattern_actions(robot, shape, length)
    poses, _ = recorder.PoseRecorder(robot).record(
      actions[None], on_step=lambda episodes: display.advance(bar)
    )
  return actions, poses[0]


def reference(robot: base.SoftArm, shape: str, length: int = REFERENCE_LENGTH) -> Reference:
  """The reference ``shape`` of ``robot``, from the cache or simulated (and then cached)."""
  if not (isinstance(length, int) and length >= 1):
    raise ValueError(f"reference length must be a positive integer, got {length!r}")
  _check_shape(shape)
  config = _config(robot, shape, length)
  key = hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:12]
  path = storage.softbench_home() / FOLDER / f"{robot.name}-{shape}-n{length}-{key}.npz"
  return storage.found_or_made(
    path, lambda: _load_cached(path, config), lambda: _generated(robot, config, path), "reference"
  )


def _generated(robot: base.SoftArm, config: dict, path: pathlib.Path) -> Reference:
  """The reference of ``config`` simulated on ``robot`` (``_simulate``), then cached at ``path``."""
  shape, length = config["shape"], config["length"]
  actions, poses = _simulate(robot, shape, length)
  arrays = {"actions": actions, "poses": poses}
  storage.write_cache_file(path, storage.npz_bytes(arrays), "cached reference")
  storage.write_cache_file(
    path.with_suffix(".json"),
    json.dumps({"config": config, "sha256": storage.arrays_sha256(arrays)}, indent=2) + "\n",
    "cached reference's description",
  )
  return Reference(shape, actions, poses)
