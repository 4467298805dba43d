"""Runs an agent through one episode of a task in physics and scores it (``softbench.metrics``).

At every control step the agent sees the observation, its action is applied for one control
period, and the pose each scored module reached is compared with the target it was shown.
"""

import pathlib
import sys
import time

from dm_control.rl import control
import numpy as np

from softbench import agents
from softbench import episodes
from softbench import progress as progress_bars
from softbench.episodes import snapshots as episode_snapshots

KEEP_INTERVAL_S = 60.0  # (s) Least time between two keepings of an unfinished episode.


def agent_label(agent: agents.Agent) -> str:
  return f"{type(agent).__name__} seed {agent.seed}"


def run_episode(
  env: control.Environment,
  agent: agents.Agent,
  task: str,
  show_progress: bool = False,
  unfinished: pathlib.Path | None = None,
) -> episodes.Episode:
  """One episode of ``env`` driven by ``agent``.

  ``unfinished``: where the episode is kept while it runs, at most every ``KEEP_INTERVAL_S``, if
  the agent can resume one (``Agent.episode_state``); an episode kept there by an interrupted
  run goes on from where it stopped, its steps so far replayed in physics (not asked of the
  agent), the same bit for bit as without the interruption. The file is removed at the end.

  Raises:
    ValueError: the agent returned an action of the wrong shape, non-finite or outside [-1, 1].
  """
  time_step = env.reset()
  scored = env.task.scored_modules()
  if agent.uses_simulator:
    agent.bind(env.physics)
  agent.reset(agents.EpisodeInfo(task, scored))
  if unfinished is not None and agent.episode_state() is None:
    unfinished = None  # Nothing to resume this agent from.
  kept = None if unfinished is None else episode_snapshots.load_partial(unfinished)
  replayed, agent_state = ([], None) if kept is None else kept
  if len(replayed):
    print(
      f"resuming: {agent_label(agent)} on {task} from step {len(replayed)} of {env.task.num_steps}",
      file=sys.stderr,
    )
  targets, poses, actions, rewards = [], [time_step.observation["poses"]], [], []
  progress = progress_bars.counting(show_progress, transient=True)
  kept_at = time.monotonic()
  with progress:
    bar = progress.add_task(f"{agent_label(agent)} on {task}", total=env.task.num_steps)
    while not time_step.last():
      targets.append(time_step.observation["target"])
      if len(actions) < len(replayed):
        action = np.array(replayed[len(actions)])
      else:
        if agent_state is not None:  # The replay is over: the agent goes on from its state.
          agent.restore_episode_state(agent_state)
          agent_state = None
        action = np.asarray(agent.act(time_step.observation), dtype=float)
      actions.append(action)
      time_step = env.step(action)
      poses.append(time_step.observation["poses"])
      rewards.append(time_step.reward)
      progress.advance(bar)
      if unfinished is not None and time.monotonic() - kept_at >= KEEP_INTERVAL_S:
        if len(actions) > len(replayed):
          episode_snapshots.save_partial(unfinished, actions, agent.episode_state())
        kept_at = time.monotonic()
  if unfinished is not None:
    unfinished.unlink(missing_ok=True)
  poses = np.array(poses)
  return episodes.Episode(
    task,
    scored,
    np.array(targets),
    poses[1:, np.array(scored) - 1],
    poses,
    np.array(actions),
    np.array(rewards),
  )
