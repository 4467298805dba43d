"""A sweep's plan run as Ray tasks, and its records written as their settings complete.

Each build and each evaluation is one Ray task of one core (a babbling collection: up to
``cluster.COLLECTION_CORES``), given the results of the builds it needs, so Ray runs the graph in
its order and in parallel; a build the data home holds is shipped instead (``shipping``). The
builds are submitted at once; an evaluation only once its agent is built and the builds that can
run leave a core free (``releasable``): Ray shares the cores fairly between kinds of task, so
evaluations submitted early would delay the trainings that the sweep's end waits for. A task
whose worker dies is run again (``cluster.MAX_RETRIES``). Each finished episode is kept at once
(``episodes.snapshots``), so an interrupted sweep resumes; once a setting's seeds are all in, its
record (``run.assemble_record``, as ``softbench run`` makes it) is saved (``saving.save``) and
its kept episodes go (an Exp1S or continual run: its record, kept seeds and heat map as
``softbench run --protocol`` leaves them; ``kinds``). A task's error is not
retried: the settings that need it fail, and the others go on.

A record's wall time is the sweep's, from its start to that record; its provenance is the
driver's, taken at the start, with the device the workers trained on.
"""

from collections.abc import Iterable
from collections.abc import Mapping
import pathlib
import time

import ray

from smpl.files import first_line
from softbench.records import provenance
from softbench.sweep import cluster
from softbench.sweep import display
from softbench.sweep import grid
from softbench.sweep import kinds
from softbench.sweep import relay
from softbench.sweep import shipping
from softbench.sweep import tasks

_POLL_SECONDS = 0.5  # (s) How often the display is refreshed while no task finishes.
_BUILD = ray.remote(tasks.build)
_EVALUATE = ray.remote(tasks.evaluate)


def _failure(error: ray.exceptions.RayError) -> str:
  """A task's error on one line: the exception the task raised, or what befell its worker."""
  cause = error.cause if isinstance(error, ray.exceptions.RayTaskError) else error
  return f"{type(cause).__name__}: {first_line(cause)}"


def _build_cores(plan: grid.Plan) -> dict[grid.Build, int]:
  """The cores each build of ``plan`` to run asks for (the cluster asked once)."""
  collection = cluster.collection_cores()
  return {
    build: collection if build.kind == "dataset" else 1
    for build in plan.builds
    if build not in plan.found
  }


def _submit_builds(
  plan: grid.Plan, build_cores: Mapping[grid.Build, int], states: relay.Relay | None
) -> tuple[dict[grid.Build, ray.ObjectRef], dict[ray.ObjectRef, grid.Build]]:
  """Submits every build of ``plan``, each asking for its ``build_cores`` and given the refs of
  the builds it needs (a shipped one's put in the object store) and the relay its bars send their
  states to (``states``, if any); each build's ref, and the build of each submitted ref."""
  environment = cluster.runtime_env()
  refs, work = {}, {}
  for build in plan.builds:
    if build in plan.found:
      refs[build] = ray.put(shipping.read(build.files))
      continue
    refs[build] = _BUILD.options(
      name=build.label,
      num_cpus=build_cores[build],
      max_retries=cluster.MAX_RETRIES,
      runtime_env=environment,
    ).remote(
      build.kind,
      build.arguments,
      build.files,
      *(refs[need] for need in build.needs),
      states=states,
    )
    work[refs[build]] = build
  return refs, work


def _submit_evaluation(
  evaluation: grid.Evaluation,
  refs: dict[grid.Build, ray.ObjectRef],
  states: relay.Relay | None,
  environment: dict,
) -> ray.ObjectRef:
  needed = () if evaluation.agent is None else (refs[evaluation.agent],)
  return _EVALUATE.options(
    name=evaluation.label,
    num_cpus=1,
    max_retries=cluster.MAX_RETRIES,
    runtime_env=environment,
  ).remote(evaluation.run, evaluation.seed, *needed, states=states)


def releasable(
  held: list[grid.Evaluation],
  builds: Iterable[grid.Build],
  finished: set,
  cores: int,
  build_cores: Mapping[grid.Build, int],
) -> list[grid.Evaluation]:
  """The ``held`` evaluations to submit now: none while the unfinished ``builds`` whose needs are
  all ``finished`` ask for every one of the ``cores``; else those whose agent is finished (or
  that need none)."""
  runnable = [build for build in builds if build not in finished and _ready(build, finished)]
  if sum(build_cores[build] for build in runnable) >= cores:
    return []
  return [evaluation for evaluation in held if _ready(evaluation, finished)]


def execute(
  plan: grid.Plan, results: pathlib.Path, show_progress: bool
) -> tuple[list[pathlib.Path], dict[str, str]]:
  """Runs ``plan`` on the Ray this process is connected to; the records written in
  ``results`` (in the order they were) and the settings that failed (by ``grid.setting_name``)
  with the error that failed them, on one line.

  Raises:
    ValueError: a node runs other source than this machine (one line).
    KeyboardInterrupt: Ctrl-C; the outstanding tasks are cancelled first.
  """
  started = time.perf_counter()
  origin = provenance.provenance(cluster.check_nodes())
  outcomes = {run: {} for run in plan.settings}
  for (run, seed), outcome in plan.resumed.items():
    outcomes[run][seed] = outcome
  written, failures = [], {}

  def complete(run: grid.GridSetting) -> None:
    if len(outcomes[run]) < run.seeds or run in failures:
      return
    in_order = [outcomes[run][seed] for seed in range(run.seeds)]
    wall_time_s = time.perf_counter() - started
    files = kinds.of(run).save(run, origin, in_order, plan.taken[run], wall_time_s, results)
    written.append(files[0])

  states = relay.Relay() if show_progress else None  # The workers' bars, if shown.
  build_cores = _build_cores(plan)
  refs, work = _submit_builds(plan, build_cores, states)
  environment = cluster.runtime_env()
  builds, held = list(work.values()), list(plan.evaluations)
  pending, finished, failed = list(work), set(plan.found), 0
  cores = cluster.cores()
  try:
    with display.Display(len(work) + len(held), len(plan.settings), show_progress) as shown:
      for run in plan.settings:  # Those whose every seed was kept.
        complete(run)
      while pending or held:
        released = releasable(held, builds, finished, cores, build_cores)
        held = [evaluation for evaluation in held if evaluation not in released]
        for evaluation in released:
          ref = _submit_evaluation(evaluation, refs, states, environment)
          work[ref] = evaluation
          pending.append(ref)
        ready, pending = ray.wait(pending, num_returns=len(pending), timeout=_POLL_SECONDS)
        for ref in ready:  # In submission order: a build before the evaluations it feeds.
          task = work[ref]
          finished.add(task)
          try:
            value = ray.get(ref)
          except ray.exceptions.RayError as error:
            failed += 1
            if isinstance(task, grid.Evaluation):
              failures.setdefault(task.run, _failure(error))
            continue
          if isinstance(task, grid.Build):
            shipping.write_missing(value)
          else:
            kinds.of(task.run).keep(task.run, task.seed, value)
            outcomes[task.run][task.seed] = value
            complete(task.run)
        running = sum(_ready(work[ref], finished) for ref in pending)
        shown.update(len(finished) - len(plan.found), min(running, cores), failed, len(written))
        if states is not None:  # A finished task's last states came before its result.
          shown.show_workers(states.take())
  except BaseException:  # Ctrl-C, or a record that cannot be written: nothing more runs.
    for ref in pending:
      ray.cancel(ref, force=True)
    raise
  finally:
    if states is not None:
      states.close()
  return written, {grid.setting_name(run): message for run, message in failures.items()}


def _needs(task: grid.Build | grid.Evaluation) -> tuple[grid.Build, ...]:
  if isinstance(task, grid.Build):
    return task.needs
  return () if task.agent is None else (task.agent,)


def _ready(task: grid.Build | grid.Evaluation, finished: set) -> bool:
  """Whether every build ``task`` needs is ``finished``."""
  return all(need in finished for need in _needs(task))
