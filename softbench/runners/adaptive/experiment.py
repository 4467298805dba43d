"""The adaptive reaching experiment in physics: the staged procedure (``procedure``) drives one
continuous reach episode per target, and an all-modules-on episode on the same target is the
comparison.

For each target (the ``reach`` task's virtual point with environment seed = target index: module
``module``'s tip after the whole arm held a random action, so a point the arm can reach but the
module alone may not), one learned agent (trained once, ``AGENT_SEED``) acts in one episode whose
active modules change stage by stage, as on a real robot: the agent's memory and the arm's state
carry over from one stage to the next. Every stage lasts ``STAGE_SECONDS``; its error is the mean
position error of the target module's tip over the control steps after ``SETTLE_SECONDS``.

The modules other than the target module get their targets by ``helpers``
(``LearnedAgent.helper_targets``): ``complete`` (default) completes the point into a whole-arm
pose from the agent's babbling and forward models, with the inactive modules' actions held at
zero (``softbench.agents.completion``); ``nearest`` takes the nearest babbling pose only;
``share`` gives every active one the target module's remaining position error and asks the
inactive ones for nothing; ``hold`` holds each at its starting pose, so that a switched-on
neighbour only resists moving.

The all-on episode starts from the same state with the same target, runs as many control steps
as the staged one with every module active, and is scored over its last steps the same way.
Effort is the sum over control steps of the squared action entries (each in [-1, 1]: normalised
cable tension or bellows pressure; zero is passive). Two savings against all-on: over the whole
run (``effort saved = 1 - adaptive / all-on`` at the same duration, exploration included), and
while holding the target (effort per step over the scored part of the last stage, against the
same steps at the end of the all-on run).
"""

import dataclasses

import numpy as np

from softbench import agents
from softbench import metrics
from softbench import profiles
from softbench import suite
from softbench.agents import learned
from softbench.records import fields
from softbench.robots import base as robot_base
from softbench.runners import evaluation
from softbench.runners.adaptive import procedure
from softbench.suite import reach

AGENT_SEED = 0  # Every target is reached by the agent trained with this seed.
STAGE_SECONDS = 10.0  # (s) Duration of a stage: the reach task's episode (reach.REACH_SECONDS).
SETTLE_SECONDS = 5.0  # (s) Time after a stage starts before its error counts; the arms settle
# within 1.4 s after a step in actuation, the rest is left to the closed loop.
THRESHOLD_FRACTION = 0.05  # Error above which the next module is tried: this fraction of the
# arm's length from the base to the target module's tip (tendon-3 module 2: 5 mm; pneumatic-433
# module 2: 8 mm).
DEFAULT_HELPERS = learned.DEFAULT_HELPER_TARGETS  # Targets of the other modules (docstring).


@dataclasses.dataclass(frozen=True)
class Timing:
  """Control steps of a stage and of its settling part."""

  stage_steps: int
  settle_steps: int

  @property
  def scored_steps(self) -> int:
    return self.stage_steps - self.settle_steps


def timing(robot: robot_base.SoftArm, profile: profiles.Profile) -> Timing:
  """``STAGE_SECONDS`` and ``SETTLE_SECONDS`` in control steps; a profile that shortens episodes
  (``tiny``) shortens the stage to its episode length and keeps the settling proportion."""
  stage = profile.episode_length or int(round(STAGE_SECONDS / robot.control_timestep))
  settle = min(int(round(stage * SETTLE_SECONDS / STAGE_SECONDS)), stage - 1)
  return Timing(stage, settle)


def threshold_mm(robot: robot_base.SoftArm, module: int) -> float:
  """``THRESHOLD_FRACTION`` of the length from the base to ``module``'s tip, in mm."""
  return THRESHOLD_FRACTION * sum(robot.module_lengths[:module]) * metrics.MM_PER_M


@dataclasses.dataclass(frozen=True)
class TargetOutcome:
  """One target: the stages with their errors, the chosen modules, and the all-on comparison.

  Paths are the target module's tip positions (mm), the start first; ``stage_ends`` are the
  control steps at which each stage ended.
  """

  target_seed: int
  target_mm: np.ndarray  # (3,)
  stages: tuple[procedure.StageResult, ...]
  stage_ends: tuple[int, ...]
  final_active: tuple[int, ...]
  final_error_mm: float
  all_on_error_mm: float
  effort: float
  all_on_effort: float
  holding_effort: float  # Per control step, over the scored part of the last stage.
  all_on_holding_effort: float  # Per control step, over the same steps of the all-on run.
  path_mm: np.ndarray  # (steps + 1, 3)
  all_on_path_mm: np.ndarray  # (steps + 1, 3)

  @property
  def effort_saved_percent(self) -> float:
    return _saved_percent(self.effort, self.all_on_effort)

  @property
  def holding_effort_saved_percent(self) -> float:
    return _saved_percent(self.holding_effort, self.all_on_holding_effort)


def _saved_percent(effort: float, all_on_effort: float) -> float:
  return 0.0 if all_on_effort == 0 else metrics.PERCENT * (1.0 - effort / all_on_effort)


def _effort(actions: np.ndarray) -> float:
  """Sum over control steps of the squared action entries."""
  return float(np.sum(np.square(actions)))


def _settled_error_mm(tips: np.ndarray, target: np.ndarray, steps: int) -> float:
  """Mean distance (mm) of the last ``steps`` tip positions (m) to the target (m)."""
  return float(np.mean(metrics.position_error_mm(tips[-steps:], target)))


def reach_target(
  agent: learned.LearnedAgent,
  robot: robot_base.SoftArm,
  target_seed: int,
  module: int,
  stages: Timing,
  threshold: float,
) -> TargetOutcome:
  """Runs the staged procedure on the target of ``target_seed`` (module docstring), then the
  all-on comparison, with ``threshold`` in mm and the agent's own ``helper_targets``."""
  staged = procedure.ActivationProcedure(robot.num_modules, module, threshold)
  env = suite.load(
    robot, "reach", seed=target_seed, module=module, steps=staged.max_stages * stages.stage_steps
  )
  time_step = env.reset()
  target = np.array(time_step.observation["target"][0], dtype=float)
  agent.reset(agents.EpisodeInfo("reach", env.task.scored_modules()))
  tips, actions, stage_ends = [time_step.observation["poses"][module - 1, :3]], [], []
  while (stage := staged.next_stage()) is not None:
    agent.switch_modules(stage.active)
    for _ in range(stages.stage_steps):
      actions.append(agent.act(time_step.observation))
      time_step = env.step(actions[-1])
      tips.append(time_step.observation["poses"][module - 1, :3])
    stage_ends.append(len(actions))
    staged.report(_settled_error_mm(np.array(tips), target, stages.scored_steps))
  all_on = evaluation.run_episode(
    suite.load(robot, "reach", seed=target_seed, module=module, steps=len(actions)), agent, "reach"
  )
  all_on_tips = all_on.poses[:, module - 1, :3]
  actions, holding = np.array(actions), slice(-stages.scored_steps, None)
  return TargetOutcome(
    target_seed=target_seed,
    target_mm=target * metrics.MM_PER_M,
    stages=staged.results,
    stage_ends=tuple(stage_ends),
    final_active=staged.active,
    final_error_mm=staged.final_error,
    all_on_error_mm=_settled_error_mm(all_on_tips, target, stages.scored_steps),
    effort=_effort(actions),
    all_on_effort=_effort(all_on.actions),
    holding_effort=_effort(actions[holding]) / stages.scored_steps,
    all_on_holding_effort=_effort(all_on.actions[holding]) / stages.scored_steps,
    path_mm=np.array(tips) * metrics.MM_PER_M,
    all_on_path_mm=all_on_tips * metrics.MM_PER_M,
  )


def check_agent(agent: agents.Agent) -> learned.LearnedAgent:
  """Raises a one-line ValueError unless ``agent`` can act with modules switched off."""
  if not isinstance(agent, learned.LearnedAgent):
    raise ValueError(f"adaptive activation needs a learned agent, got {type(agent).__name__}")
  return agent


def reach_targets(
  agent: agents.Agent,
  robot: robot_base.SoftArm,
  targets: int,
  module: int | None,
  stages: Timing,
  threshold: float | None = None,
  helpers: str = DEFAULT_HELPERS,
  on_target=None,
) -> list[TargetOutcome]:
  """``reach_target`` for the targets of seeds 0 .. ``targets`` - 1; ``threshold`` in mm
  (default ``threshold_mm``); ``on_target()`` is called after each (a progress bar).

  Raises:
    ValueError: an agent that is not learned, a module the robot lacks, an unknown ``helpers``.
  """
  agent = check_agent(agent)
  module = reach.check_module(robot, module)
  check_helpers(helpers)
  threshold = threshold_mm(robot, module) if threshold is None else threshold
  agent, outcomes = agent.with_acting(helper_targets=helpers), []
  for seed in range(targets):
    outcomes.append(reach_target(agent, robot, seed, module, stages, threshold))
    if on_target is not None:
      on_target()
  return outcomes


def check_helpers(helpers: str) -> None:
  if helpers not in fields.HELPER_TARGETS:
    raise ValueError(
      f"unknown helpers {helpers!r}; choose one of {', '.join(fields.HELPER_TARGETS)}"
    )
