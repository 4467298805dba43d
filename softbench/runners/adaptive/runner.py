"""``softbench run --adaptive``: builds (trains or loads) the agent, reaches the virtual targets
adaptively (``experiment``) and returns the record's ``adaptive`` section (``report``). Apart
from the package so that ``softbench.runners.adaptive``'s defaults import without torch."""

from softbench import agents
from softbench import profiles
from softbench import progress as progress_bars
from softbench import robots
from softbench.agents import learned
from softbench.runners.adaptive import DEFAULT_TARGETS
from softbench.runners.adaptive import experiment
from softbench.runners.adaptive import report
from softbench.suite import reach


def run(
  robot: str,
  agent: str,
  profile: profiles.Profile,
  targets: int = DEFAULT_TARGETS,
  module: int | None = None,
  eval_mode: str = "physics",
  helpers: str = experiment.DEFAULT_HELPERS,
  show_progress: bool = False,
) -> dict:
  """Builds (trains or loads) ``agent`` with ``experiment.AGENT_SEED``, reaches ``targets``
  targets adaptively, and returns the record's ``adaptive`` section (``report.section``).

  Raises:
    ValueError: an agent that does not learn, a module the robot does not have, or unknown
      ``helpers`` (one line).
  """
  arm = robots.make(robot)
  module = reach.check_module(arm, module)
  experiment.check_helpers(helpers)
  if agents.learner(agent) is None:
    raise ValueError(
      f"--adaptive needs an agent trained on babbling "
      f"({', '.join(agents.babbling_learners())}), got {agent!r}"
    )
  acting = learned.Acting(error_source=eval_mode)
  learner = experiment.check_agent(
    agents.make(agent, arm, experiment.AGENT_SEED, profile, show_progress, acting)
  )
  stages = experiment.timing(arm, profile)
  threshold = experiment.threshold_mm(arm, module)
  progress = progress_bars.counting(show_progress, transient=True)
  with progress:
    bar = progress.add_task(f"adaptive {agent} on {robot}: targets", total=targets)
    outcomes = experiment.reach_targets(
      learner,
      arm,
      targets,
      module,
      stages,
      threshold,
      helpers,
      on_target=lambda: progress.advance(bar),
    )
  return report.section(
    outcomes, arm.num_modules, module, threshold, stages, arm.control_timestep, helpers
  )
