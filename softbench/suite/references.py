"""Reference trajectories that the robot can follow, because the robot itself traced them.

A tracking task's reference drives the simulated arm from rest with the actions of its ``Shape``
and records every module's pose after each control period (``PoseRecorder``). A planar shape bends
every module alike towards a point moving in the planar actuation space of
``SoftArm.planar_action``, in units of ``bend_amplitude`` (the actuation that bends the end
effector by ``BEND_DEG``); any other shape gives the robot's actions itself. The shapes are the
functions that ``suite.tracking_task`` registers (``softbench/suite/shapes.py``).

References are cached under ``softbench_home()/references``, keyed by a hash of the robot (its
MJCF included), the length, the shape's name and its own parameters (and, for a planar shape, the
calibration's), so that adding or changing one shape leaves every other shape's cached references
valid; a content hash is checked on every load, and a damaged one is reported
(``CorruptFileWarning``) and generated again. Processes sharing a data home generate each
reference once: the others wait for it (``storage.found_or_made``). The generating actions are
stored for replay checks; tasks show controllers only the poses.
"""

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
from softbench.robots import base
from softbench.robots import recorder
from softbench.suite import registry

REFERENCE_LENGTH = registry.REFERENCE_LENGTH  # Target poses per reference.
BEND_DEG = 60.0  # (deg) End-effector bend at one bend amplitude.
AMPLITUDE_GRID = np.linspace(0.05, 1.0, 20)  # Actuations tried when calibrating the amplitude.
SETTLE_SECONDS = 3.0  # (s) Hold per calibration actuation; longer than any settling time.
FORMAT_VERSION = 2  # 2: a shape's key holds its own parameters only (1: every shape's).
FOLDER = "references"  # In the data home.


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


def shape_named(name: str) -> registry.Shape:
  """The reference shape of tracking task ``name``.

  Raises:
    ValueError: no tracking task of that name traces a reference (one line).
  """
  found = registry.describe(name).reference if name in registry.names() else None
  if found is None:
    shapes = [task for task in registry.names() if registry.describe(task).reference]
    raise ValueError(f"unknown reference shape {name!r}; choose one of {', '.join(shapes)}")
  return found


def pattern_actions(
  robot: base.SoftArm, name: str, length: int = REFERENCE_LENGTH, amplitude: float | None = None
) -> np.ndarray:
  """The generating actions (length, action_dim) of reference ``name``; a planar shape's
  ``amplitude`` is ``bend_amplitude(robot)`` unless given."""
  shape = shape_named(name)
  if shape.planar and amplitude is None:
    amplitude = bend_amplitude(robot)
  return shape.actions(robot, length, amplitude)


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


def _config(robot: base.SoftArm, shape: registry.Shape, length: int) -> dict:
  """What a reference depends on, as its cache's description stores it: the robot, the length,
  the shape's own parameters and, for a planar shape, the calibration of ``bend_amplitude``."""
  config = {
    "format": FORMAT_VERSION,
    "robot": robot.name,
    "robot_xml_sha256": robot.physics_sha256(),
    "length": length,
    "shape": shape.name,
    "parameters": shape.parameters,
  }
  if shape.planar:
    config["calibration"] = {
      "bend_deg": BEND_DEG,
      "amplitude_grid": AMPLITUDE_GRID.tolist(),
      "settle_s": SETTLE_SECONDS,
    }
  return json.loads(json.dumps(config))  # Tuples as lists, as read back.


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
  config = _config(robot, shape_named(shape), length)
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
