"""``softbench run``: train (or reuse) an agent, evaluate it on a task over seeds, report.

For each seed the agent is built (learned agents train on the robot's babbling dataset, both
cached), then acts on one episode of the task (environment seed = the same seed); the episode's
errors per module are averaged over its steps, and the table gives their mean and standard
deviation over seeds. Every run writes a result record with full provenance.

With ``faults`` (``--fault MODULE:ACTUATOR:GAIN``, ``softbench.robots.faults``) the agent is
built for the healthy robot, as a deployed controller would be, and evaluated on the faulty one.
"""

import dataclasses
import datetime
import json
import multiprocessing
import os
import pathlib
import platform
import signal
import subprocess
import time

import numpy as np
import torch
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

import softbench
from softbench import agents
from softbench import data
from softbench import evaluation
from softbench import metrics
from softbench import profiles
from softbench import robots
from softbench import storage
from softbench import suite
from softbench.agents import learned
from softbench.data import dataset
from softbench.robots import faults as fault_model

PAPER_ROBOT = {"babbling": "tendon-3", "circle": "tendon-3", "rectangle": "tendon-3",
               "spiral": "tendon-3", "custom": "tendon-3", "reach": "pneumatic-433"}
"""The robot each task runs on in the paper (Exp2S tasks on tendon-3; reaching on the pneumatic
arm), the default of ``--robot``."""
METRICS = (("position_mm", "position (mm)"), ("orientation_deg", "orientation (deg)"),
           ("normalised_tip_percent", "tip error (%)"))
_POLL_SECONDS = 0.2  # (s) How often the parent looks at its worker processes.
RECORD_FORMAT = "softbench-result"
RECORD_VERSION = 1


@dataclasses.dataclass(frozen=True)
class RunSettings:
  task: str
  agent: str
  robot: str
  seeds: int
  profile: profiles.Profile
  eval_mode: str
  trajectory: str | None = None
  faults: tuple[fault_model.Fault, ...] = ()


def settings(task: str, agent: str, robot: str | None = None, seeds: int | None = None,
             profile: str = profiles.DEFAULT_PROFILE, eval_mode: str = "physics",
             trajectory: str | None = None, faults: tuple[str, ...] = ()) -> RunSettings:
  """Checked settings, with the defaults filled in; ``faults`` as ``MODULE:ACTUATOR:GAIN`` text.

  Raises:
    ValueError: unknown task, agent, robot, profile or eval mode, seeds < 1, a trajectory
      without the custom task or the custom task without one, a malformed fault or one that
      names no actuator of the robot (one line).
  """
  suite.describe(task)
  agents.describe(agent)
  chosen = profiles.get(profile)
  robot = robot or PAPER_ROBOT[task]
  parsed_faults = tuple(fault_model.parse(text) for text in faults)
  robots.make(robot).with_faults(parsed_faults)
  seeds = chosen.seeds if seeds is None else seeds
  dataset.check_count("seeds", seeds)
  if eval_mode not in learned.ERROR_SOURCES:
    raise ValueError(f"unknown eval mode {eval_mode!r}; choose one of "
                     f"{', '.join(learned.ERROR_SOURCES)}")
  if (trajectory is None) == (task == "custom"):
    raise ValueError("--trajectory goes with --task custom, and --task custom needs one")
  return RunSettings(task, agent, robot, seeds, chosen, eval_mode,
                     None if trajectory is None else str(trajectory), parsed_faults)


def _task_options(run: RunSettings) -> dict:
  if run.task == "custom":
    return {"trajectory": run.trajectory}
  if run.profile.episode_length is None:
    return {}
  return {"steps" if run.task == "reach" else "length": run.profile.episode_length}


def _seed_scores(score: metrics.TrackingScore) -> dict:
  """Per-module means over the episode's steps, and their average over modules."""
  result = {}
  for name, _ in METRICS:
    per_module = getattr(score, name)
    if per_module:
      result[name] = {"per_module": [s.mean for s in per_module],
                      "per_module_std_over_steps": [s.std for s in per_module],
                      "mean": score.average(name).mean}
  return result


def _git_commit() -> str | None:
  try:
    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                            check=True, cwd=pathlib.Path(__file__).parent).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain"], capture_output=True, text=True,
                           check=True, cwd=pathlib.Path(__file__).parent).stdout.strip()
  except (OSError, subprocess.CalledProcessError):
    return None
  return commit + ("-dirty" if dirty else "")


def _machine() -> dict:
  return {"platform": platform.platform(), "processor": platform.processor() or
          platform.machine(), "cpu_count": os.cpu_count(), "python": platform.python_version(),
          "torch": torch.__version__, "device": str(learned.training.default_device())}


def evaluate(agent: agents.Agent, arm: robots.SoftArm, run: RunSettings, seed: int,
             show_progress: bool = False) -> tuple[dict, tuple[int, ...]]:
  """One episode of ``run``'s task (environment seed ``seed``) on ``arm``, faults included,
  scored: the seed's record entry and the scored modules."""
  if isinstance(agent, learned.LearnedAgent):
    agent.error_source = run.eval_mode
  env = suite.load(arm, run.task, seed=seed, **_task_options(run))
  episode = evaluation.run_episode(env, agent, run.task, show_progress)
  return ({"seed": seed, "steps": len(episode.actions),
           "mean_reward": float(episode.rewards.mean()),
           **_seed_scores(episode.score(arm.length))}, episode.scored_modules)


def _run_seed(run: RunSettings, seed: int, show_progress: bool) -> tuple[dict, tuple[int, ...]]:
  """Builds (trains) the agent of ``seed`` for the healthy robot, runs one episode on the robot
  with ``run.faults`` and scores it."""
  arm = robots.make(run.robot)
  agent = agents.make(run.agent, arm, seed, run.profile, show_progress)
  return evaluate(agent, arm.with_faults(run.faults), run, seed, show_progress)


def _ignore_interrupts() -> None:
  """Worker initialiser: Ctrl-C reaches the parent only, which stops the workers itself."""
  signal.signal(signal.SIGINT, signal.SIG_IGN)


def _parallel_seeds(run: RunSettings, workers: int) -> list[tuple[dict, tuple[int, ...]]]:
  """Seeds in ``workers`` processes (one torch and MuJoCo thread each), with one progress bar.

  On Ctrl-C the workers are terminated; seeds whose checkpoints were written are reused by the
  next run."""
  progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                      TimeElapsedColumn())
  pool = multiprocessing.get_context("spawn").Pool(workers, initializer=_ignore_interrupts)
  try:
    with progress:
      bar = progress.add_task(f"{run.agent} on {run.task}: seeds ({workers} processes)",
                              total=run.seeds)
      pending = [pool.apply_async(_run_seed, (run, seed, False)) for seed in range(run.seeds)]
      while not all(result.ready() for result in pending):
        time.sleep(_POLL_SECONDS)
        progress.update(bar, completed=sum(result.ready() for result in pending))
      outcomes = [result.get() for result in pending]  # Re-raises a worker's error.
      progress.update(bar, completed=run.seeds)
    pool.close()
    return outcomes
  finally:
    pool.terminate()
    pool.join()


def execute(run: RunSettings, show_progress: bool = True, workers: int | None = None) -> dict:
  """Runs every seed, in parallel processes on every core, and returns the result record.

  The babbling dataset is collected first (on every core), so that the seeds share it.
  """
  started = time.perf_counter()
  arm = robots.make(run.robot)
  if agents.describe(run.agent).learned:
    data.collect(run.robot, samples=run.profile.samples, seed=learned.DATA_SEED,
                 progress=show_progress)
  workers = min(run.seeds, workers or os.cpu_count() or 1)
  if workers > 1:
    outcomes = _parallel_seeds(run, workers)
  else:
    outcomes = [_run_seed(run, seed, show_progress) for seed in range(run.seeds)]
  return {
      "format": RECORD_FORMAT, "version": RECORD_VERSION,
      "softbench_version": softbench.__version__, "git_commit": _git_commit(),
      "robot": run.robot, "task": run.task, "agent": run.agent, "profile": run.profile.name,
      "profile_settings": dataclasses.asdict(run.profile), "eval_mode": run.eval_mode,
      "trajectory": run.trajectory, "seeds": run.seeds,
      "faults": [fault_model.describe(arm, fault) for fault in run.faults],
      "scored_modules": list(outcomes[0][1]), "per_seed": [entry for entry, _ in outcomes],
      "wall_time_s": round(time.perf_counter() - started, 3),
      "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
      "machine": _machine(),
  }


def summary(record: dict, metric: str) -> tuple[list[metrics.Statistic], metrics.Statistic]:
  """Per-module and module-averaged mean and standard deviation over seeds of ``metric``."""
  seeds = [entry[metric] for entry in record["per_seed"] if metric in entry]
  per_module = [metrics.Statistic.of([entry["per_module"][k] for entry in seeds])
                for k in range(len(seeds[0]["per_module"]))]
  return per_module, metrics.Statistic.of([entry["mean"] for entry in seeds])


def table(record: dict) -> str:
  """The printed table: rows per scored module and their mean, columns per metric."""
  measured = [(name, label) for name, label in METRICS if name in record["per_seed"][0]]
  columns = {name: summary(record, name) for name, _ in measured}
  rows = [f"module {module}" for module in record["scored_modules"]] + ["mean"]
  header = f"{'':<10}" + "".join(f"{label:>22}" for _, label in measured)
  faulty = record.get("faults") or []
  under = f" under fault {', '.join(fault['text'] for fault in faulty)}" if faulty else ""
  lines = [f"{record['agent']} on {record['task']} ({record['robot']}{under}), profile "
           f"{record['profile']}, eval {record['eval_mode']}, {record['seeds']} seed(s): "
           f"mean ± std over seeds", header]
  for index, row in enumerate(rows):
    cells = []
    for name, _ in measured:
      per_module, average = columns[name]
      statistic = average if index == len(rows) - 1 else per_module[index]
      cells.append(f"{statistic.mean:>13.2f} ± {statistic.std:<6.2f}")
    lines.append(f"{row:<10}" + "".join(cells))
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)


def record_path(record: dict, results: pathlib.Path) -> pathlib.Path:
  stamp = record["date"].replace(":", "").replace("+0000", "Z")
  faulty = "".join(f"-fault{fault['module']}.{fault['actuator']}.{fault['gain']:g}"
                   for fault in record.get("faults") or [])
  return results / (f"{record['agent']}-{record['robot']}{faulty}-{record['task']}-"
                    f"{record['profile']}-{record['eval_mode']}-{stamp}.json")


def write_record(record: dict, path: pathlib.Path) -> None:
  storage.write_atomically(path, json.dumps(record, indent=2, sort_keys=True) + "\n")
