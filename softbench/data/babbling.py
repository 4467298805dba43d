"""Motor babbling: random actuation of every module at once, recorded as a dataset (SPEC 4).

Each sample holds a uniform random action in [-1, 1]^action_dim for one control period and then
records every module's pose, so pose index s comes before action s (layout and time convention
in ``softbench.data.dataset``). The episodes start from rest and run side by side on
``PoseRecorder``'s thread pool; episode e draws all its actions from
``seeding.rng(seed, BABBLING_STREAM, e)``, so the data depend neither on the worker count nor
on the chunking. Every ``chunk_length`` control steps the recording so far is saved
(``softbench.data.chunks``); a stopped collection resumes from its last good chunk and ends with
the same bytes as one that never stopped.
"""

from collections.abc import Sequence
import os
import pathlib
import shutil
import time

import numpy as np

from softbench import progress as progress_bars
from softbench import robots
from softbench import storage
from softbench.data import chunks
from softbench.data import dataset
from softbench.data import seeding
from softbench.robots import recorder

CHUNK_LENGTH = 50  # Control steps between two saved chunks (50 s of tendon babbling).


def babbling_actions(robot: robots.SoftArm, seed: int, lengths: Sequence[int]) -> list[np.ndarray]:
  """Each episode's (length, action_dim) actions, from its own random stream."""
  return [
    seeding.rng(seed, seeding.BABBLING_STREAM, episode).uniform(
      -1.0, 1.0, (length, robot.action_dim)
    )
    for episode, length in enumerate(lengths)
  ]


def collect(
  robot: str | robots.SoftArm,
  samples: int = dataset.DEFAULT_SAMPLES,
  seed: int = 0,
  workers: int | None = None,
  home: str | pathlib.Path | None = None,
  progress: bool = True,
  episode_length: int = dataset.EPISODE_LENGTH,
  chunk_length: int = CHUNK_LENGTH,
) -> dataset.Dataset:
  """Collects (or resumes, or finds) the babbling dataset of this config.

  Args:
    robot: A registry name such as ``tendon-3``, or a robot spec (e.g. with a changed module
      length; its MJCF is part of the config, so it gets a dataset of its own).
    samples: Total samples (control periods) over all episodes.
    seed: Seed of the action streams.
    workers: Simulation threads, ``os.cpu_count()`` by default; more than the number of
      episodes would idle. The data do not depend on it.
    home: Data home, ``storage.softbench_home()`` by default.
    progress: Show a progress bar on stderr; False prints nothing.
    episode_length: Samples per episode, at most.
    chunk_length: Control steps between saved chunks. The data do not depend on it.

  Raises:
    ValueError: bad arguments (one line).
    FloatingPointError: the simulation became unstable.
  """
  arm = dataset.resolve_robot(robot)
  config = dataset.generating_config(arm, samples, seed, episode_length)
  workers = (os.cpu_count() or 1) if workers is None else workers
  dataset.check_count("workers", workers)
  dataset.check_count("chunk_length", chunk_length)
  folder = dataset.dataset_folder(config, home)
  return storage.found_or_made(
    folder,
    lambda: _found(folder, config),
    lambda: _collected(arm, config, seed, folder, workers, chunk_length, progress),
    "babbling dataset",
    home,
  )


def _found(folder: pathlib.Path, config: dict) -> dataset.Dataset | None:
  """The dataset of ``config`` in ``folder``, None if it is not there (or damaged: reported)."""
  return storage.read_cached(
    folder / dataset.JSON_NAME,
    lambda _: dataset.read(folder, config),
    "dataset",
    "collecting it again",
    (folder / dataset.NPZ_NAME,),
  )


def _collected(
  arm: robots.SoftArm,
  config: dict,
  seed: int,
  folder: pathlib.Path,
  workers: int,
  chunk_length: int,
  progress: bool,
) -> dataset.Dataset:
  """Collects the dataset of ``config`` (action streams of ``seed``) into ``folder``, resuming its
  saved chunks (``collect``)."""
  started = time.perf_counter()
  lengths = config["episode_lengths"]
  actions = babbling_actions(arm, seed, lengths)
  pose_recorder = recorder.PoseRecorder(arm, min(workers, len(lengths)))
  resumed_step, poses_after = _record(
    pose_recorder,
    actions,
    folder / chunks.PARTIAL_FOLDER,
    chunk_length,
    progress,
    dataset.dataset_key(config),
  )
  rest_poses = pose_recorder.poses(pose_recorder.rest_state())
  poses = [
    np.concatenate([rest_poses[None], poses_after[episode, :length]])
    for episode, length in enumerate(lengths)
  ]
  arrays = {
    "actions": np.concatenate(actions),
    "poses": np.concatenate(poses),
    "episode_lengths": np.array(lengths, dtype="<i8"),
  }
  collection = {
    "wall_time_s": round(time.perf_counter() - started, 3),
    "workers": pose_recorder.workers,
    "resumed_from_step": resumed_step,
  }
  dataset.write(folder, config, arrays, collection)
  result = dataset.read(folder, config)
  shutil.rmtree(folder / chunks.PARTIAL_FOLDER)
  return result


def _record(
  pose_recorder: recorder.PoseRecorder,
  actions: list[np.ndarray],
  partial: pathlib.Path,
  chunk_length: int,
  show_progress: bool,
  collection: str,
) -> tuple[int, np.ndarray]:
  """Records every episode chunk by chunk, from the saved chunks of this ``collection`` (its
  dataset key) on.

  Episodes shorter than the longest are held at zero action to its end; those poses are
  dropped. Returns the step resumed from and the poses after each step,
  (episodes, steps, num_modules, 6).
  """
  lengths = np.array([len(episode) for episode in actions])
  held = np.zeros((len(actions), lengths.max(), pose_recorder.robot.action_dim))
  for episode, episode_actions in enumerate(actions):
    held[episode, : len(episode_actions)] = episode_actions
  layout = chunks.Layout(
    episodes=len(actions),
    steps=held.shape[1],
    num_modules=pose_recorder.robot.num_modules,
    state_size=pose_recorder.state_size,
    collection=collection,
  )
  done = chunks.resume(partial, layout)
  step = done[-1].stop if done else 0
  resumed_step = step
  states = done[-1].final_states if done else None

  def samples_after(steps: int) -> int:
    return int(np.minimum(lengths, steps).sum())

  with progress_bars.SampleProgress(
    f"babbling {pose_recorder.robot.name}",
    total=int(lengths.sum()),
    completed=samples_after(step),
    enabled=show_progress,
  ) as bar:

    def on_step(_episodes: int) -> None:
      nonlocal step
      step += 1
      bar.update(samples_after(step))

    for start in range(step, layout.steps, chunk_length):
      stop = min(start + chunk_length, layout.steps)
      poses, states = pose_recorder.record(held[:, start:stop], states, on_step=on_step)
      chunk = chunks.Chunk(start, stop, poses[:, 1:], states)
      chunks.write(partial, chunk, collection)
      done.append(chunk)
  return resumed_step, np.concatenate([chunk.poses for chunk in done], axis=1)
