"""The ``softbench`` command line. It parses arguments and calls the library; a bad input gets
one line on stderr and exit code 2, a malformed command line included."""

import argparse
import json
import os
import pathlib
import sys

from dm_control.rl import control

import softbench
from softbench import adaptive
from softbench import agents
from softbench import continual
from softbench import data
from softbench import leaderboard
from softbench import parallel_seeds
from softbench import profiles
from softbench import retrain as retrain_module
from softbench import robots
from softbench import run as run_module
from softbench import saving
from softbench import storage
from softbench import suite
from softbench import tuning
from softbench import zoo
from softbench.agents import hyperparameters
from softbench.data import dataset
from softbench.data import seeding
from softbench.leaderboard import doc_tables
from softbench.leaderboard import grid
from softbench.leaderboard import zoo_catalogue
from softbench.leaderboard import zoo_verification
from softbench.rendering import options as video_options
from softbench.rendering import video
from softbench.robots import export as model_export

EXIT_USAGE = 2
_JSON_HELP = "print JSON (for scripts) instead of a table"
EXIT_FAILURE = 1  # The run itself failed (not the input).
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it.


def _robot_overrides(args: argparse.Namespace) -> dict:
  return {"module_length": args.module_length} if args.module_length is not None else {}


def _describe(robot: robots.SoftArm) -> str:
  return (
    f"{robot.name:<15} {robot.num_modules:>7} {robot.action_dim:>10} "
    f"{robot.length * 1000:>9.0f} {robot.mass() * 1000:>8.1f}"
  )


def _robot_facts(robot: robots.SoftArm) -> dict:
  """What ``softbench robots --json`` tells of ``robot`` (SI units)."""
  return {
    "name": robot.name,
    "modules": robot.num_modules,
    "action_dim": robot.action_dim,
    "actuators_per_module": list(robot.actuators_per_module),
    "length_m": robot.length,
    "mass_kg": robot.mass(),
    "control_period_s": robot.control_timestep,
  }


def _print_json(document) -> None:
  print(json.dumps(document, indent=2, allow_nan=False))


def _robots(args: argparse.Namespace) -> None:
  header = f"{'robot':<15} {'modules':>7} {'action dim':>10} {'length mm':>9} {'mass g':>8}"
  if args.name is None:
    listed = [robots.make(name, **_robot_overrides(args)) for name in robots.BENCHMARK_ROBOTS]
    if args.json:
      _print_json([_robot_facts(robot) for robot in listed])
      return
    print(header)
    for robot in listed:
      print(_describe(robot))
    return
  robot = robots.make(args.name, **_robot_overrides(args))
  if args.json:
    _print_json(
      {
        **_robot_facts(robot),
        "spec": {field: value for field, value in model_export.spec_fields(robot)},
      }
    )
    return
  print(header)
  print(_describe(robot))
  print(
    f"\ncontrol period: {robot.control_timestep} s; actions per module: "
    f"{', '.join(map(str, robot.actuators_per_module))}"
  )
  for field, value in model_export.spec_fields(robot):
    print(f"  {field} = {value}")


def _models_export(args: argparse.Namespace) -> None:
  out = storage.check_writable(args.out, "models to", folder=True)
  chosen = [robots.make(name) for name in args.robots or robots.BENCHMARK_ROBOTS]  # Checked first.
  for robot in chosen:
    for path in model_export.export(robot, out, args.measure_speed):
      print(path)


def _tasks(args: argparse.Namespace) -> None:
  if args.json:
    _print_json(
      [
        {
          "name": task,
          "tags": list(suite.describe(task).tags),
          "description": suite.describe(task).description,
          "benchmark_robots": [robot for robot, name in suite.ALL_TASKS if name == task],
        }
        for task in suite.TASKS
      ]
    )
    return
  print(f"{'task':<10} {'tags':<24} description")
  for task in suite.TASKS:
    entry = suite.describe(task)
    print(f"{task:<10} {', '.join(entry.tags):<24} {entry.description}")
  periods = sorted(
    {(robots.make(name).control_timestep, name.split("-")[0]) for name in robots.BENCHMARK_ROBOTS},
    key=lambda item: item[1],
  )
  print(
    "\ncontrol period: "
    + "; ".join(f"{family} arms {period:g} s ({1 / period:g} Hz)" for period, family in periods)
  )
  print(
    f"{len(suite.ALL_TASKS)} (robot, task) pairs on the benchmark robots "
    f"({', '.join(robots.BENCHMARK_ROBOTS)}); every task runs on any robot"
  )


def _collect(args: argparse.Namespace) -> None:
  collected = data.collect(args.robot, samples=args.samples, seed=args.seed, workers=args.workers)
  seconds = collected.collection.get("wall_time_s")
  print(
    f"{collected.robot_name}: {collected.samples} samples in {collected.num_episodes} episodes"
    + (f" (collection took {seconds:.1f} s)" if seconds is not None else "")
  )
  print(collected.path)


def _agents(args: argparse.Namespace) -> None:
  if args.json:
    tuned = hyperparameters.load()["agents"]
    _print_json(
      [
        {
          "name": name,
          "learned": agents.describe(name).learned,
          "description": agents.describe(name).description,
          "hyperparameters": {
            robot: values["params"] for robot, values in tuned.get(name, {}).items()
          },
        }
        for name in agents.AGENTS
      ]
    )
    return
  print(f"{'agent':<10} {'learns':<7} description")
  for name in agents.AGENTS:
    entry = agents.describe(name)
    print(f"{name:<10} {'yes' if entry.learned else 'no':<7} {entry.description}")
    if args.verbose and entry.learned:
      for robot, values in hyperparameters.load()["agents"].get(name, {}).items():
        study = values["study"]
        origin = "not tuned"
        if study is not None:
          origin = (
            f"best of {sum(study['trials'].values())} trials on the {study['profile']} "
            f"profile: validation MSE {_loss(study['best']['value'])} after "
            f"{study['trial_epochs']} epochs"
          )
          if "full_budget" in study:
            origin += f", {_loss(study['full_budget']['best'])} after {study['max_epochs']}"
        settings = ", ".join(f"{key} {value:g}" for key, value in values["params"].items())
        print(f"{'':<18} {robot}: {settings} ({origin})")


def _loss(value: float | None) -> str:
  return "not finite" if value is None else f"{value:.4g}"


def _tune(args: argparse.Namespace) -> None:
  settings = tuning.settings(
    args.agent, args.robot, args.trials, args.storage, args.profile, args.study, args.epochs
  )
  summary = tuning.run(settings)
  if args.confirm:
    summary = tuning.confirm(settings, summary)
  best, previous = summary["best"], summary["previous_values"]
  trials = summary["trials"]
  print(
    f"{settings.agent} on {settings.robot}, profile {settings.profile.name}: "
    f"{trials['complete']} complete, {trials['pruned']} pruned, {trials['fail']} failed"
  )
  if previous is not None:
    print(f"previous values (trial {previous['trial']}): validation MSE {_loss(previous['value'])}")
  if best is not None:
    print(f"best trial {best['trial']}: validation MSE {_loss(best['value'])}")
    for key, value in best["params"].items():
      print(f"  {key} = {value:g}")
  if "full_budget" in summary:
    check = summary["full_budget"]
    print(
      f"at the profile's {check['epochs']} epochs: previous values "
      f"{_loss(check['previous'])}, best {_loss(check['best'])}"
    )
  path = pathlib.Path(args.summary) if args.summary else tuning.summary_path(settings)
  tuning.write_summary(summary, path)
  print(f"study summary: {path}")
  if args.adopt:
    tuning.adopt(summary)
    print(f"adopted as {settings.agent}'s values on {settings.robot}: {hyperparameters.PATH}")


def _run_protocol(args: argparse.Namespace) -> None:
  if args.protocol != continual.PROTOCOL:
    raise ValueError(
      f"unknown protocol {args.protocol!r}; {continual.PROTOCOL} is the one with a "
      f"table of its own (exp2s and exp2r are the tasks on tendon-3 and "
      f"pneumatic-433: softbench run --task TASK --agent AGENT)"
    )
  if args.agent != "smpl":
    raise ValueError(
      f"--protocol {args.protocol} trains SMPL's columns in sequence; it takes "
      f"--agent smpl, got {args.agent!r}"
    )
  given = [
    flag
    for flag, value in (
      ("--task", args.task),
      ("--robot", args.robot),
      ("--trajectory", args.trajectory),
      ("--video", args.video),
      ("--module", args.module),
      ("--targets", args.targets),
      ("--helpers", args.helpers),
    )
    if value is not None
  ]
  given += (["--adaptive"] if args.adaptive else []) + (["--fault"] if args.fault else [])
  if given or args.eval != "physics":
    raise ValueError(
      f"--protocol {args.protocol} fixes its robots, tasks and loops; drop "
      f"{', '.join(given) or '--eval'}"
    )
  profile = profiles.get(args.profile)
  family = args.family or continual.DEFAULT_FAMILY
  continual.protocol(family)  # Checked before anything runs.
  record = continual.execute(
    profile, args.seeds, workers=args.workers, keep_seeds=True, family=family
  )
  files = saving.save(continual, record, pathlib.Path(args.results), _json_copy(args))
  continual.finish(record, files)


def _number(name: str, text: str, kind: type) -> int | float:
  try:
    return kind(text)
  except ValueError:
    raise ValueError(f"{name} must be a number, got {text!r}") from None


# The video flags (``_add_video_arguments``), their attributes and defaults.
_VIDEO_FLAGS = (
  ("--width", "width", str(video_options.DEFAULT_WIDTH)),
  ("--height", "height", str(video_options.DEFAULT_HEIGHT)),
  ("--fps", "fps", f"{video_options.DEFAULT_FPS:g}"),
  ("--camera", "camera", video_options.DEFAULT_CAMERA),
  ("--frames-per-step", "frames_per_step", "1"),
)


def _video_options(args: argparse.Namespace) -> video_options.VideoOptions:
  given = {
    name: default if getattr(args, name) is None else getattr(args, name)
    for _, name, default in _VIDEO_FLAGS
  }
  return video_options.VideoOptions(
    _number("width", given["width"], int),
    _number("height", given["height"], int),
    _number("fps", given["fps"], float),
    given["camera"],
    _number("frames per step", given["frames_per_step"], int),
  )


def _video_flags_given(args: argparse.Namespace) -> list[str]:
  return [flag for flag, name, _ in _VIDEO_FLAGS if getattr(args, name) is not None]


def _run(args: argparse.Namespace) -> None:
  if args.video is None and _video_flags_given(args):
    given = _video_flags_given(args)
    raise ValueError(
      f"{', '.join(given)} {'goes' if len(given) == 1 else 'go'} with --video FILE.mp4"
    )
  _check_record_arguments(args)
  if args.workers is not None:  # Before any collection or training starts.
    dataset.check_count("workers", args.workers)
  if args.protocol is not None:
    return _run_protocol(args)
  if args.family is not None:
    raise ValueError("--family goes with --protocol exp1s; a task's robot is --robot")
  if args.task is None:
    raise ValueError("softbench run needs --task TASK (or --protocol exp1s)")
  settings = run_module.settings(
    args.task,
    args.agent,
    args.robot,
    args.seeds,
    args.profile,
    args.eval,
    args.trajectory,
    args.module,
    args.adaptive,
    args.targets,
    args.helpers,
    tuple(args.fault),
  )
  if args.video and settings.adaptive:
    raise ValueError("--video renders one seed's episode; --adaptive draws its own figure")
  video_request = None
  if args.video:
    video_request = run_module.VideoRequest(
      video_options.check_video_path(args.video), _video_options(args)
    )
  record, episodes = run_module.execute_episodes(settings, keep_seeds=True, workers=args.workers)
  files = saving.save(run_module, record, pathlib.Path(args.results), _json_copy(args))
  run_module.finish(settings, record, files, episodes, video_request)


def _render(args: argparse.Namespace) -> None:
  options = _video_options(args)
  path = video_options.check_video_path(args.out)
  seed = _number("seed", args.seed, int)
  seeding.check_seed(seed)
  settings = run_module.settings(
    args.task, args.agent, args.robot, 1, args.profile, args.eval, args.trajectory
  )
  episode = run_module.seed_episode(settings, seed, show_progress=True)
  run_module.write_video(settings, seed, episode, run_module.VideoRequest(path, options))


def _add_video_arguments(parser: argparse.ArgumentParser) -> None:
  """The flags of ``_VIDEO_FLAGS``; left out, they are None (``_video_options`` fills in)."""
  parser.add_argument(
    "--width", help=f"frame width in pixels, even (default {video_options.DEFAULT_WIDTH})"
  )
  parser.add_argument(
    "--height", help=f"frame height in pixels, even (default {video_options.DEFAULT_HEIGHT})"
  )
  parser.add_argument("--fps", help=f"frames per second (default {video_options.DEFAULT_FPS:g})")
  parser.add_argument(
    "--camera",
    help=f"one of {', '.join(video_options.CAMERAS)} (default {video_options.DEFAULT_CAMERA})",
  )
  parser.add_argument(
    "--frames-per-step",
    help="frames per control step, to show the motion within each step "
    "(default 1: the pose at the end of every step, after a frame of "
    "the start)",
  )


def _add_profile_argument(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--profile",
    default=profiles.DEFAULT_PROFILE,
    help=f"one of {', '.join(profiles.PROFILES)} (default {profiles.DEFAULT_PROFILE})",
  )


def _add_eval_argument(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--eval", default="physics", help="physics (default), model or open-loop: the error fed back"
  )


def _add_record_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--results",
    default="leaderboard/results",
    help="folder of the result records (default leaderboard/results)",
  )
  parser.add_argument("--json", help="also write the result record to this file")


def _json_copy(args: argparse.Namespace) -> pathlib.Path | None:
  return pathlib.Path(args.json) if args.json else None


def _check_record_arguments(args: argparse.Namespace) -> None:
  """Refuses a ``--results`` or ``--json`` that could not be written, before the run."""
  storage.check_writable(args.results, "result records to", folder=True)
  if args.json:
    storage.check_writable(args.json, "result record")


def _leaderboard(args: argparse.Namespace) -> None:
  if args.grid is not None:
    print(" ".join(grid.lists()[args.grid]))
    return
  results = pathlib.Path(args.results)
  board = leaderboard.build(results)
  print(leaderboard.text.report(board, results))
  if args.write:
    for path in [
      *leaderboard.write(board, results, pathlib.Path(args.out)),
      *doc_tables.write(board, results),
    ]:
      print(f"wrote {path}")


def _retrain(args: argparse.Namespace) -> None:
  settings = retrain_module.settings(
    args.agent, args.robot, tuple(args.fault), args.profile, args.task, args.seeds, args.baseline
  )
  _check_record_arguments(args)
  record = retrain_module.execute(settings)
  saving.save(retrain_module, record, pathlib.Path(args.results), _json_copy(args))


def _zoo_folder(args: argparse.Namespace, create: bool = False) -> pathlib.Path:
  """The zoo a ``softbench zoo`` command works on: ``--zoo``, else the one in use."""
  chosen = pathlib.Path(args.zoo) if args.zoo else zoo.location()
  if chosen is None:
    raise ValueError(f"the zoo is turned off (${zoo.VARIABLE}={zoo.OFF}); name one with --zoo DIR")
  if create:
    return storage.check_writable(chosen, "the zoo", folder=True)
  if not chosen.is_dir():
    raise ValueError(
      f"no zoo at {chosen}: not a folder (name one with --zoo DIR or ${zoo.VARIABLE})"
    )
  return chosen


def _zoo_list(args: argparse.Namespace) -> None:
  folder = _zoo_folder(args)
  entries = zoo.read_manifest(folder)
  print(f"{'kind':<15} {'KiB':>8} {'records':>7}  path")
  for path, entry in sorted(entries.items()):
    print(f"{entry.kind:<15} {entry.bytes / 1024:>8.1f} {len(entry.records):>7}  {path}")
  print(
    f"{len(entries)} files, {zoo.size_bytes(entries) / 2**20:.1f} MiB of "
    f"{zoo.BUDGET_BYTES / 2**20:.0f} MiB ({folder})"
  )
  for problem in zoo.check_files(folder):
    print(f"problem: {problem}")


def _zoo_add(args: argparse.Namespace) -> None:
  family = None
  if args.protocol is not None:
    if args.protocol != continual.PROTOCOL:
      raise ValueError(f"unknown protocol {args.protocol!r}; the zoo keeps {continual.PROTOCOL}'s")
    family = args.family or continual.DEFAULT_FAMILY
  elif args.family is not None:
    raise ValueError(f"--family goes with --protocol {continual.PROTOCOL}")
  chosen = zoo_catalogue.setting(args.agent, args.robot, family, args.profile, args.seeds)
  folder = _zoo_folder(args, create=True)
  linked = zoo_catalogue.records_of(chosen, pathlib.Path(args.results))
  files = zoo_catalogue.cache_files(chosen)
  added, skipped = zoo.add(
    [(path, kind) for _, path, kind in files],
    {path: linked[seed] for seed, path, kind in files if kind == "agent"},
    folder,
  )
  for entry in added:
    print(
      f"added {entry.path} ({entry.kind}, {entry.bytes / 1024:.1f} KiB, "
      f"{len(entry.records)} records)"
    )
  for path in skipped:
    print(f"skipped {path.name}: its training has not started in the data home")
  print(
    f"zoo: {zoo.size_bytes(zoo.read_manifest(folder)) / 2**20:.1f} MiB of "
    f"{zoo.BUDGET_BYTES / 2**20:.0f} MiB ({folder})"
  )


def _zoo_verify(args: argparse.Namespace) -> None:
  folder = _zoo_folder(args)
  for name in args.agents or ():
    agents.describe(name)
  problems = zoo.check_files(folder)
  if problems:
    raise ValueError(f"{folder}: {problems[0]} ({len(problems)} problems; see softbench zoo list)")

  def report(check) -> None:
    verdict = "identical" if check.identical else f"DIFFERS: {check.detail}"
    print(f"{check.record} seed {check.seed}: {verdict} ({check.seconds:.1f} s)", flush=True)

  checks = zoo_verification.verify(
    pathlib.Path(args.results),
    folder,
    tuple(args.agents) if args.agents else None,
    args.quick,
    report,
  )
  differing = [check for check in checks if not check.identical]
  print(
    f"{len(checks) - len(differing)} of {len(checks)} re-scored seeds identical to their records"
  )
  if differing:
    raise ZooMismatch(f"{len(differing)} re-scored seeds differ from their records")


class ZooMismatch(RuntimeError):
  """``softbench zoo verify`` found a record that the zoo's weights do not reproduce."""


_FAULT_HELP = (
  "a faulty actuator, MODULE:ACTUATOR:GAIN (module from 1, actuator from 0 within "
  "the module: cable xpos, ypos, xneg, yneg of a tendon arm, bellows 0.. (MJCF "
  "bellows1..) of the pneumatic arm; gain in [0, 1], 0 punctured); repeat for "
  "several"
)


class _OneLineErrorParser(argparse.ArgumentParser):
  """An argument parser (and, through ``add_subparsers``, its subcommands' parsers) whose
  command-line errors are one line, pointing at ``--help`` instead of printing the usage."""

  def error(self, message: str):
    self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
  parser = _OneLineErrorParser(prog="softbench", description=__doc__.split(".")[0] + ".")
  parser.add_argument("--version", action="version", version=f"softbench {softbench.__version__}")
  commands = parser.add_subparsers(dest="command", required=True)
  robots_parser = commands.add_parser("robots", help="list the benchmark robots or describe one")
  robots_parser.add_argument("name", nargs="?", help="e.g. tendon-3 or pneumatic-433")
  robots_parser.add_argument("--module-length", type=float, help="module length in m")
  robots_parser.add_argument("--json", action="store_true", help=_JSON_HELP)
  robots_parser.set_defaults(run=_robots)
  tasks_parser = commands.add_parser("tasks", help="list the tasks of the suite")
  tasks_parser.add_argument("--json", action="store_true", help=_JSON_HELP)
  tasks_parser.set_defaults(run=_tasks)
  collect_parser = commands.add_parser(
    "collect",
    help="record (or resume) a motor-babbling dataset",
    description="Motor babbling with every module active, cached under $SOFTBENCH_HOME "
    "(default $XDG_CACHE_HOME/softbench, or ~/.cache/softbench); an interrupted "
    "collection resumes.",
  )
  collect_parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  collect_parser.add_argument(
    "--samples",
    type=int,
    default=data.DEFAULT_SAMPLES,
    help=f"control periods to record (default {data.DEFAULT_SAMPLES})",
  )
  collect_parser.add_argument("--seed", type=int, default=0, help="seed of the random actions")
  collect_parser.add_argument(
    "--workers", type=int, default=None, help="simulation threads (default: every core)"
  )
  collect_parser.set_defaults(run=_collect)
  agents_parser = commands.add_parser("agents", help="list the agents")
  agents_parser.add_argument(
    "--verbose", action="store_true", help="also show each learned agent's hyperparameters"
  )
  agents_parser.add_argument(
    "--json", action="store_true", help=_JSON_HELP + ", hyperparameters included"
  )
  agents_parser.set_defaults(run=_agents)
  tune_parser = commands.add_parser(
    "tune",
    help="tune a learned agent's hyperparameters with Optuna",
    description="Runs (or resumes) an Optuna study of the agent's hyperparameters on the "
    "babbling validation split; the same budget for every agent.",
  )
  tune_parser.add_argument("--agent", required=True, help="a learned agent, e.g. smpl or lstm")
  tune_parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  tune_parser.add_argument(
    "--trials",
    type=int,
    default=tuning.DEFAULT_TRIALS,
    help=f"finished trials the study should hold (default "
    f"{tuning.DEFAULT_TRIALS}); "
    "re-running adds the missing ones",
  )
  tune_parser.add_argument(
    "--storage", help="Optuna storage URL (default: sqlite:///$SOFTBENCH_HOME/tuning.db)"
  )
  tune_parser.add_argument(
    "--profile",
    default=profiles.DEFAULT_PROFILE,
    help=f"data and epoch budget: one of {', '.join(profiles.PROFILES)} "
    f"(default {profiles.DEFAULT_PROFILE})",
  )
  tune_parser.add_argument(
    "--epochs",
    type=int,
    help="epoch budget of each trial's inverse model (default: the "
    "profile's; fewer buys more trials)",
  )
  tune_parser.add_argument("--study", help="study name (default AGENT-ROBOT-PROFILE)")
  tune_parser.add_argument(
    "--summary", help="where to write the study summary (default $SOFTBENCH_HOME/tuning/STUDY.json)"
  )
  tune_parser.add_argument(
    "--confirm",
    action="store_true",
    help="then train the previous and the best values at the profile's "
    "full epoch budget and report both",
  )
  tune_parser.add_argument(
    "--adopt",
    action="store_true",
    help="commit the best values as the agent's hyperparameters on the "
    "robot (softbench/agents/hyperparameters.json)",
  )
  tune_parser.set_defaults(run=_tune)
  run_parser = commands.add_parser(
    "run",
    help="train (or reuse) an agent and score it on a task over seeds",
    description="Collects or reuses the babbling dataset, trains or reuses the agent (cached "
    "by config), evaluates it (closed loop in physics unless --eval says otherwise) "
    "and prints the errors over seeds.",
  )
  run_parser.add_argument("--task", help=f"one of {', '.join(suite.TASKS)}")
  run_parser.add_argument(
    "--protocol",
    help=f"{continual.PROTOCOL}: SMPL learns tendon-1 .. "
    f"tendon-5 (or another --family's arms) in sequence; "
    f"prints the paper's Exp1S table and the forgetting "
    f"matrix",
  )
  run_parser.add_argument(
    "--family",
    help=f"with --protocol {continual.PROTOCOL}: the tendon "
    f"family whose arms 1 .. 5 SMPL learns, one of "
    f"{', '.join(robots.TENDON_FAMILIES)} (default "
    f"{continual.DEFAULT_FAMILY})",
  )
  run_parser.add_argument("--agent", required=True, help=f"one of {', '.join(agents.AGENTS)}")
  run_parser.add_argument(
    "--robot", help="default: the task's robot in the paper (tendon-3; pneumatic-433 for reach)"
  )
  run_parser.add_argument("--seeds", type=int, help="number of seeds (default: the profile's)")
  run_parser.add_argument(
    "--workers",
    type=int,
    help="processes that run seeds in parallel (default: one per core, at "
    "most one per seed); more than the cores keeps them all busy "
    "while the last seeds run, e.g. 3 for 5 seeds on 2 cores",
  )
  _add_profile_argument(run_parser)
  _add_eval_argument(run_parser)
  run_parser.add_argument("--trajectory", help="target poses for --task custom (.npy or .csv)")
  run_parser.add_argument(
    "--module", type=int, help="the module that reaches (--task reach; default 2)"
  )
  run_parser.add_argument(
    "--adaptive",
    action="store_true",
    help="--task reach with adaptive module activation: the reaching "
    "module alone, then its neighbours while they lower the error",
  )
  run_parser.add_argument(
    "--targets",
    type=int,
    help=f"virtual targets of --adaptive (default {adaptive.DEFAULT_TARGETS})",
  )
  run_parser.add_argument(
    "--helpers",
    help="what --adaptive asks of the other active modules: "
    "share (default; the reaching module's error) or "
    "hold (their starting pose)",
  )
  _add_record_arguments(run_parser)
  run_parser.add_argument("--video", help="also render seed 0's episode to this .mp4 file")
  _add_video_arguments(run_parser)
  run_parser.add_argument(
    "--fault",
    action="append",
    default=[],
    help=_FAULT_HELP + "; the agent is trained on the healthy robot",
  )
  run_parser.set_defaults(run=_run)
  board_parser = commands.add_parser(
    "leaderboard",
    help="rank the result records per robot and task",
    description="Checks every result record (schema and integrity hash) and prints, per robot "
    "and task, the newest record of each agent, profile and eval mode, ranked by "
    "position error: mean ± std over seeds [95% bootstrap CI].",
  )
  board_parser.add_argument(
    "--results",
    default=str(leaderboard.DEFAULT_RESULTS),
    help=f"folder of the result records (default {leaderboard.DEFAULT_RESULTS})",
  )
  board_parser.add_argument(
    "--write",
    action="store_true",
    help="also regenerate README.md and index.html in --out, and the "
    "results tables of the checkout's README.md and docs/*.md",
  )
  board_parser.add_argument(
    "--out",
    default=str(leaderboard.DEFAULT_OUT),
    help=f"folder of the pages (default {leaderboard.DEFAULT_OUT})",
  )
  board_parser.add_argument(
    "--grid",
    choices=tuple(grid.lists()),
    help="print the names on one axis of the grid make leaderboard fills, and nothing else",
  )
  board_parser.set_defaults(run=_leaderboard)
  render_parser = commands.add_parser(
    "render",
    help="render an agent's episode of a task to an MP4 video",
    description="Trains (or reuses) the agent for one seed, runs its episode and renders it "
    "off-screen (the MUJOCO_GL you set, else egl, else osmesa) with the target "
    "trail and the achieved tip path.",
  )
  render_parser.add_argument("--task", required=True, help=f"one of {', '.join(suite.TASKS)}")
  render_parser.add_argument("--agent", required=True, help=f"one of {', '.join(agents.AGENTS)}")
  render_parser.add_argument("--robot", help="default: the task's robot in the paper")
  render_parser.add_argument("--out", required=True, help="the video file (.mp4)")
  render_parser.add_argument("--seed", default="0", help="agent and environment seed (default 0)")
  _add_profile_argument(render_parser)
  _add_eval_argument(render_parser)
  render_parser.add_argument("--trajectory", help="target poses for --task custom (.npy or .csv)")
  _add_video_arguments(render_parser)
  render_parser.set_defaults(run=_render)
  retrain_parser = commands.add_parser(
    "retrain",
    help="retrain the faulty module's SMPL column after an actuator fault",
    description="Collects babbling on the faulty robot, retrains only the faulty module's "
    "column of the smpl agent (and the forward models from that module on), and "
    "compares the errors before the fault, under it, after retraining one column "
    "and of a centralised baseline retrained from scratch, with wall times.",
  )
  retrain_parser.add_argument(
    "--agent",
    default=retrain_module.RETRAINED_AGENT,
    help="the agent to adapt (smpl, the default, is the only one)",
  )
  retrain_parser.add_argument("--robot", help="default: the task's robot in the paper")
  retrain_parser.add_argument(
    "--fault", action="append", default=[], help=_FAULT_HELP + "; every fault in one module"
  )
  retrain_parser.add_argument(
    "--task", default=retrain_module.DEFAULT_TASK, help=f"default {retrain_module.DEFAULT_TASK}"
  )
  retrain_parser.add_argument(
    "--baseline",
    default=retrain_module.DEFAULT_BASELINE,
    help=f"centralised baseline retrained from scratch (default {retrain_module.DEFAULT_BASELINE})",
  )
  retrain_parser.add_argument("--seeds", type=int, help="number of seeds (default: the profile's)")
  _add_profile_argument(retrain_parser)
  _add_record_arguments(retrain_parser)
  retrain_parser.set_defaults(run=_retrain)
  _add_zoo_parser(commands)
  models = commands.add_parser("models", help="exported MJCF models")
  models_commands = models.add_subparsers(dest="models_command", required=True)
  export_parser = models_commands.add_parser("export", help="write models/<name>/ for every robot")
  export_parser.add_argument("--out", default="models", help="output folder (default: models)")
  export_parser.add_argument(
    "--robots",
    nargs="+",
    metavar="ROBOT",
    help="export only these robots (default: every benchmark robot)",
  )
  export_parser.add_argument(
    "--measure-speed", action="store_true", help="also measure simulation speed into speed.json"
  )
  export_parser.set_defaults(run=_models_export)
  return parser


def _add_zoo_parser(commands) -> None:
  zoo_parser = commands.add_parser(
    "zoo",
    help="trained weights kept in the repository: list, add, verify",
    description="The zoo holds the weights behind leaderboard records (and the saved state of "
    "unfinished trainings); softbench run takes them instead of training.",
  )
  zoo_commands = zoo_parser.add_subparsers(dest="zoo_command", required=True)
  zoo_help = f"the zoo folder (default ${zoo.VARIABLE}, else zoo/ of the checkout)"
  list_parser = zoo_commands.add_parser("list", help="the zoo's files, sizes and records")
  list_parser.add_argument("--zoo", help=zoo_help)
  list_parser.set_defaults(run=_zoo_list)
  add_parser = zoo_commands.add_parser(
    "add",
    help="copy a setting's trained weights (or unfinished training) into the zoo",
    description="Copies each seed's checkpoint and forward models from the data home into the "
    "zoo, or the saved state of a training still under way, and links the records "
    "in --results that they stand behind.",
  )
  add_parser.add_argument("--agent", help="a learned agent")
  add_parser.add_argument("--robot", help="the robot it was trained on")
  add_parser.add_argument("--protocol", help=f"{continual.PROTOCOL}: the Exp1S networks instead")
  add_parser.add_argument(
    "--family",
    help=f"with --protocol {continual.PROTOCOL}: one of {', '.join(robots.TENDON_FAMILIES)}",
  )
  add_parser.add_argument("--seeds", type=int, help="seeds 0 .. N-1 (default: the profile's)")
  _add_profile_argument(add_parser)
  add_parser.add_argument(
    "--results", default=str(leaderboard.DEFAULT_RESULTS), help="folder of the records to link"
  )
  add_parser.add_argument("--zoo", help=zoo_help)
  add_parser.set_defaults(run=_zoo_add)
  verify_parser = zoo_commands.add_parser(
    "verify",
    help="re-score records from the zoo alone and compare them",
    description="Re-scores, in an empty data home, every record the zoo's agents stand "
    "behind, seed by seed, and compares each figure with the record's.",
  )
  verify_parser.add_argument("--agents", nargs="+", metavar="AGENT", help="only these agents")
  verify_parser.add_argument(
    "--quick", action="store_true", help="seed 0 only, one record per checkpoint"
  )
  verify_parser.add_argument(
    "--results", default=str(leaderboard.DEFAULT_RESULTS), help="folder of the records"
  )
  verify_parser.add_argument("--zoo", help=zoo_help)
  verify_parser.set_defaults(run=_zoo_verify)


_CACHING_COMMANDS = ("collect", "run", "render", "retrain", "tune")  # They write to the data home.


def main(argv: list[str] | None = None) -> int:
  try:
    args = build_parser().parse_args(argv)
  except SystemExit as done:  # --help (0), or a malformed command line (one line, 2).
    return done.code
  parallel_seeds.one_line_warnings()
  try:
    with parallel_seeds.sigterm_as_interrupt():
      if args.command in _CACHING_COMMANDS:  # Before any work: a home that takes no file fails
        storage.check_home()  # at once, not after the first seed.
      args.run(args)
  except (ValueError, FileNotFoundError, FloatingPointError, video.RenderingUnavailable) as error:
    print(f"softbench: error: {dataset.first_line(error)}", file=sys.stderr)
    return EXIT_USAGE
  except (
    parallel_seeds.WorkerDied,
    video.RenderingFailed,
    continual.ForgettingDetected,
    ZooMismatch,
  ) as error:
    print(f"softbench: error: {dataset.first_line(error)}", file=sys.stderr)
    return EXIT_FAILURE
  except control.PhysicsError as error:  # MuJoCo's state blew up during an episode.
    print(
      f"softbench: error: the simulation became unstable ({dataset.first_line(error)})",
      file=sys.stderr,
    )
    return EXIT_FAILURE
  except KeyboardInterrupt:
    print("softbench: interrupted; run the same command again to resume", file=sys.stderr)
    return EXIT_INTERRUPTED
  except BrokenPipeError:  # The reader went away (softbench leaderboard | head).
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return EXIT_FAILURE
  except OSError as error:  # A file or folder that cannot be read or written, a full disk.
    print(f"softbench: error: {_describe_os_error(error)}", file=sys.stderr)
    return EXIT_FAILURE
  return 0


def _describe_os_error(error: OSError) -> str:
  """``error`` in one line: the file and the system's reason when it names them."""
  if error.filename is None or not error.strerror:
    return dataset.first_line(error)
  target = f" -> {error.filename2}" if error.filename2 is not None else ""
  return f"{error.filename}{target}: {error.strerror}"


if __name__ == "__main__":
  sys.exit(main())
