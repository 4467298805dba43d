"""Runs an agent through one episode of a task in physics and scores it (``softbench.metrics``).

At every control step the agent sees the observation, its action is applied for one control
period, and the pose each scored module reached is compared with the target it was shown.
"""

from dm_control.rl import control
import numpy as np

from softbench import agents
from softbench import episodes
from softbench import progress as progress_bars


def agent_label(agent: agents.Agent) -> str:
  return f"{type(agent).__name__} seed {agent.seed}"


def run_episode(
  env: control.Environment, agent: agents.Agent, task: str, show_progress: bool = False
) -> episodes.Episode:
  """One episode of ``env`` driven by ``agent``.

  Raises:
    ValueError: the agent returned an action of the wrong shape, non-finite or outside [-1, 1].
  """
  time_step = env.reset()
  scored = env.task.scored_modules()
  if agent.uses_simulator:
    agent.bind(env.physics)
  agent.reset(agents.EpisodeInfo(task, scored))
  targets, poses, actions, rewards = [], [time_step.observation["poses"]], [], []
  progress = progress_bars.counting(show_progress, transient=True)
  with progress:
    bar = progress.add_task(f"{agent_label(agent)} on {task}", total=env.task.num_steps)
    while not time_step.last():
      targets.append(time_step.observation["target"])
      action = np.asarray(agent.act(time_step.observation), dtype=float)
      actions.append(action)
      time_step = env.step(action)
      poses.append(time_step.observation["poses"])
      rewards.append(time_step.reward)
      progress.advance(bar)
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
