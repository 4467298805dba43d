"""The settings of a ``softbench run``: checked once, before any collection or training, so that
bad input is one line (``settings``); and what they mean for the task (``task_options``) and for
how a learned agent acts (``acting``)."""

import dataclasses

from softbench import agents
from softbench import profiles
from softbench import robots
from softbench import suite
from softbench.agents import learned
from softbench.data import dataset
from softbench.records import fields
from softbench.robots import faults as fault_model
from softbench.runners import adaptive as adaptive_activation
from softbench.runners.adaptive import experiment as adaptive_experiment
from softbench.suite import reach
from softbench.suite import trajectories


@dataclasses.dataclass(frozen=True)
class RunSettings:
  task: str
  agent: str
  robot: str
  seeds: int
  profile: profiles.Profile
  eval_mode: str
  trajectory: str | None = None
  module: int | None = None  # The reaching module (task reach); None: the task's default.
  adaptive: bool = False
  targets: int | None = None  # Virtual targets of an adaptive run.
  helpers: str | None = None  # How a learned agent completes partial targets (helper_targets of
  # LearnedAgent); None: the task gives whole targets, or the agent does not learn from babbling.
  faults: tuple[fault_model.Fault, ...] = ()
  given: str | None = None  # The part of a custom trajectory's targets its file gives (``Given``).


def settings(
  task: str,
  agent: str,
  robot: str | None = None,
  seeds: int | None = None,
  profile: str = profiles.DEFAULT_PROFILE,
  eval_mode: str = "physics",
  trajectory: str | None = None,
  module: int | None = None,
  adaptive: bool = False,
  targets: int | None = None,
  helpers: str | None = None,
  faults: tuple[str, ...] = (),
  given: str | None = None,
) -> RunSettings:
  """Checked settings, with the defaults filled in; ``faults`` as ``MODULE:ACTUATOR:GAIN`` text,
  ``given`` as ``suite.trajectories.Given`` text.

  Raises:
    ValueError: unknown task, agent, robot, profile or eval mode, seeds outside 1 ..
      ``profiles.MAX_SEEDS``, a trajectory
      without the custom task or the custom task without one, an unreadable or malformed
      trajectory file, a module with another task than reach or out of range, adaptive with
      another task than reach, a non-learned agent or more than one seed, targets without
      adaptive, targets < 1, unknown helpers or helpers where nothing is completed, a malformed
      fault or one that names no actuator of the robot, ``given`` without a trajectory or
      malformed (one line).
  """
  suite.describe(task)
  agents.describe(agent)
  chosen = profiles.get(profile)
  robot = robot or suite.describe(task).paper_robot
  parsed_faults = tuple(fault_model.parse(text) for text in faults)
  robots.make(robot).with_faults(parsed_faults)
  _check_adaptive(task, agent, robot, seeds, module, adaptive, targets)
  if adaptive and parsed_faults:
    raise ValueError("--fault and --adaptive do not go together yet")
  seeds = (1 if adaptive else chosen.seeds) if seeds is None else seeds
  dataset.check_count("seeds", seeds, profiles.MAX_SEEDS)
  if eval_mode not in fields.ERROR_SOURCES:
    raise ValueError(
      f"unknown eval mode {eval_mode!r}; choose one of {', '.join(fields.ERROR_SOURCES)}"
    )
  if (trajectory is None) == (task == "custom"):
    raise ValueError("--trajectory goes with --task custom, and --task custom needs one")
  if given is not None and trajectory is None:
    raise ValueError("--given goes with --task custom and its --trajectory")
  if given is not None:
    given = trajectories.Given.parse(given, robots.make(robot)).text
  if trajectory is not None:  # Read now: a bad file is refused before any collection or training.
    trajectories.load_trajectory(trajectory, robots.make(robot), given)
  if adaptive:
    targets = adaptive_activation.DEFAULT_TARGETS if targets is None else targets
  run = RunSettings(
    task,
    agent,
    robot,
    seeds,
    chosen,
    eval_mode,
    None if trajectory is None else str(trajectory),
    module,
    adaptive,
    targets,
    None,
    parsed_faults,
    given,
  )
  return dataclasses.replace(run, helpers=_helpers(run, helpers))


def _check_adaptive(
  task: str,
  agent: str,
  robot: str,
  seeds: int | None,
  module: int | None,
  adaptive: bool,
  targets: int | None,
) -> None:
  """The checks of ``--module``, ``--adaptive`` and ``--targets``."""
  if module is not None and task != "reach":
    raise ValueError("--module goes with --task reach")
  if module is not None:
    reach.check_module(robots.make(robot), module)
  if adaptive and task != "reach":
    raise ValueError(f"--adaptive goes with --task reach, not {task!r}: it reaches a point")
  if adaptive and agents.learner(agent) is None:
    raise ValueError(
      f"--adaptive needs an agent trained on babbling "
      f"({', '.join(agents.babbling_learners())}), not {agent!r}"
    )
  if adaptive and seeds not in (None, 1):
    raise ValueError("--adaptive uses one trained agent (seed 0); vary --targets, not --seeds")
  if targets is not None and not adaptive:
    raise ValueError("--targets goes with --adaptive")
  if targets is not None:
    dataset.check_count("targets", targets, adaptive_activation.MAX_TARGETS)


def _helpers(run: RunSettings, helpers: str | None) -> str | None:
  """How ``run``'s agent completes its task's partial targets: ``helpers``, or by default
  ``learned.DEFAULT_HELPER_TARGETS``; None where nothing is completed (whole targets, or an
  agent that does not learn from babbling).

  Raises:
    ValueError: unknown ``helpers``, or ``helpers`` where nothing is completed (one line).
  """
  if helpers is not None:
    adaptive_experiment.check_helpers(helpers)
  if suite.gives_whole_targets(run.robot, run.task, **task_options(run)):
    if helpers is not None:
      raise ValueError(f"--helpers completes partial targets; task {run.task!r} gives whole ones")
    return None
  if agents.learner(run.agent) is None:
    if helpers is not None:
      raise ValueError(
        f"--helpers goes with an agent trained on babbling "
        f"({', '.join(agents.babbling_learners())}), not {run.agent!r}"
      )
    return None
  return learned.DEFAULT_HELPER_TARGETS if helpers is None else helpers


def acting(run: RunSettings) -> learned.Acting:
  """How ``run``'s agent acts, if it is trained on babbling: its eval mode and helper targets."""
  return learned.Acting(run.eval_mode, run.helpers or learned.DEFAULT_HELPER_TARGETS)


def task_options(run: RunSettings) -> dict:
  """The options ``suite.load`` gets for ``run``'s task (episode length, trajectory and the
  part of it given)."""
  if run.task == "custom":
    return {"trajectory": run.trajectory, **({} if run.given is None else {"given": run.given})}
  options = {} if run.module is None else {"module": run.module}
  return {**options, **suite.length_options(run.task, run.profile.episode_length)}
