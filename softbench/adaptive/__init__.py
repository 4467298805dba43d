"""Adaptive module activation (paper, section "Adaptive Module Activation Experiment"; SPEC 7):
reach a virtual point with one module, switching on its neighbours only while they lower the
error, and measure the actuation effort this saves against all modules on.

- ``procedure``: the staged procedure as a state machine, independent of physics.
- ``experiment``: drives it in physics, one continuous reach episode per target, and the
  all-modules-on comparison.
- ``report``: the ``adaptive`` section of the result record, and the printed table.
- ``plot``: the figure (error per stage over targets, paths traced), from the record alone.

``softbench run --task reach --agent smpl --adaptive [--targets N] [--module K]`` calls ``run``.
Every learned agent can take part: inactive modules get zero actuation (``LearnedAgent``'s
``active_modules``); SMPL's inactive columns keep observing, and a centralised baseline still
computes every output, masked the same way.
"""

from softbench import agents
from softbench import profiles
from softbench import progress as progress_bars
from softbench import robots
from softbench.adaptive import experiment
from softbench.adaptive import procedure
from softbench.adaptive import report
from softbench.suite import reach

DEFAULT_TARGETS = 20  # Virtual targets of ``softbench run --adaptive``.


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
  learner = experiment.check_agent(
    agents.make(agent, arm, experiment.AGENT_SEED, profile, show_progress)
  )
  learner.error_source = eval_mode
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


__all__ = ["DEFAULT_TARGETS", "experiment", "procedure", "report", "run"]
