"""``softbench retrain``: adapt SMPL to an actuator fault by retraining one column, and compare.

For each seed, on the task's targets (those of the healthy robot, ``softbench.suite.load``):

  before     the smpl agent trained on the healthy robot, on the healthy robot;
  under      the same agent on the faulty robot, no retraining (a deployed controller);
  retrained  the same agent with the faulty module's column retrained on babbling of the faulty
             robot, every other column bit-identical (``softbench.agents.adaptation``);
  baseline   a centralised baseline (``--baseline``, default lstm) trained from scratch on the
             faulty robot's babbling.

The babbling of the faulty robot is collected once, before any retraining, so the wall times of
the two retrainings count training only. A wall time comes from the run that trained the
checkpoint; one reused from the cache keeps the time recorded when it was trained. The result
record is ``softbench run``'s, with ``per_seed`` holding the retrained agent under the fault and a
``fault`` section holding every condition, the wall times and what was retrained.
"""

import dataclasses
import pathlib
import time

from smpl import fitting
from softbench import agents
from softbench import data
from softbench import metrics
from softbench import profiles
from softbench import robots
from softbench.agents import adaptation
from softbench.agents import learned
from softbench.learning import inverse as inverse_training
from softbench.records import provenance
from softbench.robots import faults as fault_model
from softbench.runners import run as run_module
from softbench.runners import run_settings

DEFAULT_TASK = "spiral"
DEFAULT_BASELINE = "lstm"
RETRAINED_AGENT = "smpl"
CONDITIONS = (
  ("before", "before the fault (healthy robot)"),
  ("under", "under the fault, no retraining"),
  ("retrained", "smpl, column {column} retrained"),
  ("baseline", "{baseline}, retrained from scratch"),
)


@dataclasses.dataclass(frozen=True)
class RetrainSettings:
  run: run_settings.RunSettings  # The smpl agent's run, faults included.
  baseline: str

  @property
  def module(self) -> int:
    return self.run.faults[0].module


def settings(
  agent: str = RETRAINED_AGENT,
  robot: str | None = None,
  faults: tuple[str, ...] = (),
  profile: str = profiles.DEFAULT_PROFILE,
  task: str = DEFAULT_TASK,
  seeds: int | None = None,
  baseline: str = DEFAULT_BASELINE,
) -> RetrainSettings:
  """Checked settings; ``faults`` as ``MODULE:ACTUATOR:GAIN`` text, all in one module.

  Raises:
    ValueError: an agent other than smpl, no fault or faults in several modules, a baseline
      that is not a centralised learned agent, or anything ``softbench run`` refuses (one line).
  """
  if agent != RETRAINED_AGENT:
    raise ValueError(
      f"retrain adapts the {RETRAINED_AGENT} agent (one column per module), got {agent!r}"
    )
  if agents.learner(baseline) is None or baseline == RETRAINED_AGENT:
    learners = [name for name in agents.babbling_learners() if name != RETRAINED_AGENT]
    raise ValueError(
      f"baseline must be a centralised learned agent ({', '.join(learners)}), got {baseline!r}"
    )
  if not faults:
    raise ValueError(f"retrain needs a fault: --fault {fault_model.FAULT_FORMAT}")
  run = run_settings.settings(task, agent, robot, seeds, profile, faults=tuple(faults))
  adaptation.faulty_module(robots.make(run.robot).with_faults(run.faults))
  return RetrainSettings(run, baseline)


def _timed_baseline(
  settings: RetrainSettings, faulty: robots.SoftArm, seed: int, show_progress: bool
) -> tuple[agents.Agent, float | None, bool]:
  """The baseline trained on the faulty robot, the wall time of its training and whether it was
  trained now (the checkpoint did not exist, or was damaged and written again)."""
  profile = settings.run.profile
  path = learned.checkpoint_path(settings.baseline, faulty, seed, profile, per_module=False)
  cached = _file_identity(path)
  started = time.perf_counter()
  acting = run_settings.acting(settings.run)
  agent = agents.make(settings.baseline, faulty, seed, profile, show_progress, acting)
  trained_now = _file_identity(path) != cached
  if trained_now:
    adaptation.write_wall_time(path, round(time.perf_counter() - started, 3))
  return agent, adaptation.read_wall_time(path), trained_now


def _file_identity(path: pathlib.Path) -> tuple[int, int] | None:
  """The file's inode and modification time (ns), which a checkpoint written again changes; None
  if there is none."""
  try:
    status = path.stat()
  except OSError:
    return None
  return status.st_ino, status.st_mtime_ns


def _seed(settings: RetrainSettings, seed: int, show_progress: bool) -> dict:
  """Every condition's scores on one seed, and the wall times of the retrainings."""
  run = settings.run
  healthy = robots.make(run.robot)
  faulty = healthy.with_faults(run.faults)
  smpl = agents.make(
    RETRAINED_AGENT, healthy, seed, run.profile, show_progress, run_settings.acting(run)
  )
  before, scored = run_module.evaluate(smpl, healthy, run, seed, show_progress)
  under, _ = run_module.evaluate(smpl, faulty, run, seed, show_progress)
  retrained = adaptation.retrain_column(smpl, faulty, run.profile, show_progress)
  identical = adaptation.columns_bit_identical(
    smpl.inverse, retrained.agent.inverse, retrained.column
  )
  after, _ = run_module.evaluate(retrained.agent, faulty, run, seed, show_progress)
  baseline, baseline_seconds, baseline_now = _timed_baseline(settings, faulty, seed, show_progress)
  from_scratch, _ = run_module.evaluate(baseline, faulty, run, seed, show_progress)
  return {
    "scores": {"before": before, "under": under, "retrained": after, "baseline": from_scratch},
    "retraining": {
      "retrained": {"wall_time_s": retrained.wall_time_s, "trained_now": retrained.trained_now},
      "baseline": {"wall_time_s": baseline_seconds, "trained_now": baseline_now},
    },
    "other_columns_bit_identical": identical,
    "scored_modules": scored,
  }


def execute(settings: RetrainSettings, show_progress: bool = True) -> dict:
  """Collects both robots' babbling, runs every seed (one after the other) and returns the
  result record."""
  started = time.perf_counter()
  origin = provenance.provenance(str(fitting.default_device()))
  run = settings.run
  healthy = robots.make(run.robot)
  faulty = healthy.with_faults(run.faults)
  data.collect(
    healthy, samples=run.profile.samples, seed=inverse_training.DATA_SEED, progress=show_progress
  )
  faulty_data = data.collect(
    faulty, samples=run.profile.samples, seed=inverse_training.DATA_SEED, progress=show_progress
  )
  seeds = [_seed(settings, seed, show_progress) for seed in range(run.seeds)]
  module = settings.module
  record = {
    "format": run_module.RECORD_FORMAT,
    "version": run_module.RECORD_VERSION,
    **origin,
    "robot": run.robot,
    "task": run.task,
    "agent": RETRAINED_AGENT,
    "profile": run.profile.name,
    "profile_settings": dataclasses.asdict(run.profile),
    "eval_mode": run.eval_mode,
    "trajectory": None,
    "seeds": run.seeds,
    "faults": [fault_model.describe(healthy, fault) for fault in run.faults],
    "scored_modules": list(seeds[0]["scored_modules"]),
    "per_seed": [entry["scores"]["retrained"] for entry in seeds],
    "fault": {
      "module": module,
      "retrained_column": module,
      "retrained_forward_models": list(range(module, healthy.num_modules + 1)),
      "baseline": settings.baseline,
      "faulty_babbling": {
        "samples": faulty_data.samples,
        "collection_wall_time_s": faulty_data.collection.get("wall_time_s"),
      },
      "other_columns_bit_identical": all(entry["other_columns_bit_identical"] for entry in seeds),
      "conditions": {
        name: {"per_seed": [entry["scores"][name] for entry in seeds]} for name, _ in CONDITIONS
      },
      "retraining_wall_time_s": {
        name: [entry["retraining"][name]["wall_time_s"] for entry in seeds]
        for name in ("retrained", "baseline")
      },
      "trained_now": {
        name: [entry["retraining"][name]["trained_now"] for entry in seeds]
        for name in ("retrained", "baseline")
      },
    },
    "wall_time_s": round(time.perf_counter() - started, 3),
  }
  return record


def _cell(values: list) -> str:
  if not values or any(value is None for value in values):
    return f"{'not timed':>22}"
  statistic = metrics.Statistic.of(values)
  return f"{statistic.mean:>13.1f} ± {statistic.std:<6.1f}"


def table(record: dict) -> str:
  """Rows per condition, columns per metric (module mean, mean ± std over seeds), and the wall
  time of each retraining."""
  fault = record["fault"]
  measured = [
    (name, label)
    for name, label in run_module.METRICS
    if name in fault["conditions"]["before"]["per_seed"][0]
  ]
  faults = ", ".join(f"{f['text']} ({f['actuator_name']})" for f in record["faults"])
  lines = [
    f"{record['agent']} on {record['task']} ({record['robot']}), fault {faults}, profile "
    f"{record['profile']}, {record['seeds']} seed(s): module mean, mean ± std over seeds",
    f"{'':<36}" + "".join(f"{label:>22}" for _, label in measured) + f"{'retraining (s)':>22}",
  ]
  for name, label in CONDITIONS:
    entries = fault["conditions"][name]["per_seed"]
    cells = []
    for metric, _ in measured:
      statistic = metrics.Statistic.of([entry[metric]["mean"] for entry in entries])
      cells.append(f"{statistic.mean:>13.2f} ± {statistic.std:<6.2f}")
    timing = fault["retraining_wall_time_s"].get(name)
    cells.append(_cell(timing) if timing is not None else "")
    lines.append(
      f"{label.format(column=fault['module'], baseline=fault['baseline']):<36}" + "".join(cells)
    )
  babbling = fault["faulty_babbling"]
  seconds = babbling["collection_wall_time_s"]
  lines.append(
    f"babbling of the faulty robot: {babbling['samples']} samples"
    + (f", collected in {seconds:.1f} s" if seconds is not None else "")
  )
  lines.append(
    "other columns bit-identical after retraining: "
    + ("yes" if fault["other_columns_bit_identical"] else "NO")
  )
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)


def record_path(record: dict, results: pathlib.Path) -> pathlib.Path:
  """``softbench run``'s record name with ``-retrain`` after the agent."""
  path = run_module.record_path(record, results)
  return path.with_name(path.name.replace(f"{record['agent']}-", f"{record['agent']}-retrain-", 1))
