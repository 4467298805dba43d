"""The ``softbench`` command line. It parses arguments and calls the library; a bad input gets
one line on stderr and exit code 2, a malformed command line included.

Only the command that runs has its arguments built, and a command's arguments and handler import
the modules they need themselves: ``softbench --help`` and the listings start without loading
torch, Ray or the plotting stack (6 s here, when every command's modules were imported)."""

import argparse
from collections.abc import Callable
from collections.abc import Collection
import dataclasses
import difflib
import os
import pathlib
import sys
import warnings

from dm_control.rl import control

import softbench
from softbench import profiles
from softbench import storage
from softbench import terminal
from softbench import zoo

EXIT_USAGE = 2
_JSON_HELP = "print JSON (for scripts) instead of a table"
_SEEDS_HELP = f"number of seeds, at most {profiles.MAX_SEEDS:,} (default: the profile's)"
EXIT_FAILURE = 1  # The run itself failed (not the input).
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it.
# The video flags (``_add_video_arguments``) by attribute: ``VideoOptions`` fields.
_VIDEO_OPTIONS = ("width", "height", "fps", "camera", "frames_per_step")
# The flags of ``softbench run`` that a task's run takes and ``--protocol exp1s`` does not.
_TASK_RUN_OPTIONS = (
  "task",
  "robot",
  "trajectory",
  "given",
  "video",
  "module",
  "targets",
  "helpers",
  "adaptive",
  "fault",
)


def _flags_given(args: argparse.Namespace, names: tuple[str, ...]) -> list[str]:
  """The flags among ``names`` (attributes of ``args``) that the command line set: not left at
  None, False (a switch) or [] (a repeatable flag)."""
  unset = lambda value: value is None or value is False or value == []
  return [f"--{name.replace('_', '-')}" for name in names if not unset(getattr(args, name))]


def _robot_overrides(args: argparse.Namespace) -> dict:
  return {"module_length": args.module_length} if args.module_length is not None else {}


def _robots(args: argparse.Namespace) -> None:
  from softbench import listings

  if args.json:
    return terminal.print_json(listings.robots_document(args.name, **_robot_overrides(args)))
  terminal.show(listings.robots_table(args.name, **_robot_overrides(args)))


def _models_export(args: argparse.Namespace) -> None:
  from softbench import robots
  from softbench.robots import export as model_export

  out = storage.check_writable(args.out, "models to", folder=True)
  chosen = [robots.make(name) for name in args.robots or robots.REGISTERED_ROBOTS]  # Checked first.
  for robot in chosen:
    for path in model_export.export(robot, out, args.measure_speed):
      print(path)


def _tasks(args: argparse.Namespace) -> None:
  from softbench import listings

  if args.json:
    return terminal.print_json(listings.tasks_document())
  terminal.show(listings.tasks_table())


def _collect(args: argparse.Namespace) -> None:
  from softbench import data

  collected = data.collect(args.robot, samples=args.samples, seed=args.seed, workers=args.workers)
  print(collected.describe())
  print(collected.path)


def _agents(args: argparse.Namespace) -> None:
  from softbench import listings

  if args.json:
    return terminal.print_json(listings.agents_document())
  terminal.show(listings.agents_table(args.verbose))


def _tune(args: argparse.Namespace) -> None:
  from softbench import tuning

  settings = tuning.settings(
    args.agent, args.robot, args.trials, args.storage, args.profile, args.study, args.epochs
  )
  tuning.tune(settings, args.confirm, args.summary, args.adopt)


def _run_protocol(args: argparse.Namespace) -> None:
  from softbench.runners import continual
  from softbench.runners import saving

  settings = continual.settings(
    args.protocol,
    args.agent,
    args.profile,
    args.family,
    args.seeds,
    args.eval,
    _flags_given(args, _TASK_RUN_OPTIONS),
  )
  record = continual.execute(
    settings.profile, settings.seeds, workers=args.workers, keep_seeds=True, family=settings.family
  )
  saving.save(
    continual,
    record,
    pathlib.Path(args.results),
    _json_copy(args),
    lambda files: continual.finish(record, files),
  )


def _video_request(args: argparse.Namespace, path: str):
  """A ``run.VideoRequest`` of the options the video flags give, to ``path``; both checked."""
  from softbench.rendering import options as video_options
  from softbench.runners import run as run_module

  options = video_options.from_text(**{name: getattr(args, name) for name in _VIDEO_OPTIONS})
  return run_module.VideoRequest(video_options.check_video_path(path), options)


def _run(args: argparse.Namespace) -> None:
  from softbench.data import dataset
  from softbench.runners import run as run_module
  from softbench.runners import saving

  video_flags = _flags_given(args, _VIDEO_OPTIONS)
  if args.video is None and video_flags:
    raise ValueError(
      f"{', '.join(video_flags)} {'goes' if len(video_flags) == 1 else 'go'} with --video FILE.mp4"
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
    args.given,
  )
  if args.video and settings.adaptive:
    raise ValueError("--video renders one seed's episode; --adaptive draws its own figure")
  video_request = _video_request(args, args.video) if args.video else None
  record, episodes = run_module.execute_episodes(settings, keep_seeds=True, workers=args.workers)
  saving.save(
    run_module,
    record,
    pathlib.Path(args.results),
    _json_copy(args),
    lambda files: run_module.finish(settings, record, files, episodes, video_request),
  )


def _render(args: argparse.Namespace) -> None:
  from softbench.data import seeding
  from softbench.rendering import options as video_options
  from softbench.runners import run as run_module

  request = _video_request(args, args.out)
  seed = video_options.parse_number("seed", args.seed, int)
  seeding.check_seed(seed)
  settings = run_module.settings(
    args.task, args.agent, args.robot, 1, args.profile, args.eval, args.trajectory, given=args.given
  )
  run_module.render_seed(settings, seed, request)


def _add_video_arguments(parser: argparse.ArgumentParser) -> None:
  """The flags of ``_VIDEO_OPTIONS``; left out, they are None (``from_text`` takes the default)."""
  from softbench.rendering import options as video_options

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


def _add_results_argument(
  parser: argparse.ArgumentParser, what: str = "folder of the result records"
) -> None:
  from softbench import records

  parser.add_argument(
    "--results",
    default=str(records.DEFAULT_FOLDER),
    help=f"{what} (default {records.DEFAULT_FOLDER}, the committed leaderboard's)",
  )


def _add_record_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import records

  parser.add_argument(
    "--results",
    help=f"folder to write the result record to (default $SOFTBENCH_HOME/"
    f"{records.USER_FOLDER_NAME}, your own runs; the committed leaderboard's is "
    f"{records.DEFAULT_FOLDER})",
  )
  parser.add_argument("--json", help="also write the result record to this file")
  _add_physics_argument(parser)


def _add_physics_argument(parser: argparse.ArgumentParser) -> None:
  from softbench.robots import versions

  parser.add_argument(
    "--physics",
    metavar="VERSION",
    help=f"the physics version to simulate, of {', '.join(versions.VERSIONS)} (default: the "
    f"installed one, {versions.current().name}); another is refused, saying how to install it",
  )


def _check_physics(args: argparse.Namespace) -> None:
  """Refuses a ``--physics`` that is unknown or not the installed one (one line)."""
  from softbench.robots import versions

  if args.physics is not None:
    versions.check(args.physics)


def _json_copy(args: argparse.Namespace) -> pathlib.Path | None:
  return pathlib.Path(args.json) if args.json else None


def _check_record_arguments(args: argparse.Namespace) -> None:
  """Refuses a ``--physics`` this installation does not run, and a ``--results`` or ``--json``
  that could not be written, before the run."""
  from softbench import records

  _check_physics(args)
  if args.results is None:
    args.results = str(records.user_folder())
  storage.check_writable(args.results, "result records to", folder=True)
  if args.json:
    storage.check_writable(args.json, "result record")


def _sweep(args: argparse.Namespace) -> None:
  from softbench import sweep
  from softbench.runners import continual

  _check_physics(args)
  if args.protocol is None and args.families is not None:
    raise ValueError(f"--families goes with --protocol {continual.PROTOCOL}")
  if args.protocol is not None:
    continual.settings(args.protocol, "smpl")  # An unknown protocol: its one line.
  sweep.sweep(
    args.robots,
    args.tasks,
    args.agents,
    args.results,
    args.profile,
    args.seeds,
    args.eval,
    args.address,
    args.data_home,
    families=(args.families or [continual.DEFAULT_FAMILY]) if args.protocol else (),
    dry_run=args.dry_run,
  )


def _leaderboard(args: argparse.Namespace) -> None:
  from softbench import leaderboard
  from softbench.leaderboard import doc_tables
  from softbench.leaderboard import filters
  from softbench.leaderboard import grid

  if args.grid is not None:
    print(" ".join(grid.lists()[args.grid]))
    return
  results = pathlib.Path(args.results)
  if not results.exists():  # A mistyped folder is no empty leaderboard.
    raise ValueError(f"no folder of result records at {results}")
  record_filter = filters.RecordFilter(
    *(
      tuple(names or ())
      for names in (args.robots, args.tasks, args.agents, args.profiles, args.physics)
    )
  )
  if args.write and record_filter.active:
    raise ValueError(
      "--write writes the whole leaderboard; drop --robots, --tasks, --agents, --profiles and "
      "--physics"
    )
  board = leaderboard.build(results, record_filter)
  print(leaderboard.text.report(board, results, record_filter.describe()))
  if args.write:
    for path in [
      *leaderboard.write(board, results, pathlib.Path(args.out)),
      *doc_tables.write(board, results),
    ]:
      print(f"wrote {path}")


def _retrain(args: argparse.Namespace) -> None:
  from softbench.runners import retrain as retrain_module
  from softbench.runners import saving

  settings = retrain_module.settings(
    args.agent, args.robot, tuple(args.fault), args.profile, args.task, args.seeds, args.baseline
  )
  _check_record_arguments(args)
  record = retrain_module.execute(settings)
  saving.save(retrain_module, record, pathlib.Path(args.results), _json_copy(args))


def _zoo_list(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.zoo import listing as zoo_listing

  terminal.show(zoo_listing.contents(zoo.chosen_folder(args.zoo)))


def _zoo_add(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_catalogue
  from softbench.zoo import listing as zoo_listing

  chosen = zoo_catalogue.requested_setting(
    args.agent, args.robot, args.protocol, args.family, args.profile, args.seeds, args.seed
  )
  folder = zoo.chosen_folder(args.zoo, create=True)
  added, skipped, unchecked = zoo_catalogue.add(
    chosen, pathlib.Path(args.results), folder, args.link_unchecked
  )
  print(zoo_listing.additions(added, skipped, folder, unchecked))


def _zoo_remove(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_catalogue
  from softbench.zoo import listing as zoo_listing

  chosen = zoo_catalogue.requested_setting(
    args.agent, args.robot, args.protocol, args.family, args.profile, args.seeds, args.seed
  )
  folder = zoo.chosen_folder(args.zoo)
  print(zoo_listing.removals(zoo_catalogue.remove(chosen, folder), folder))


def _zoo_verify(args: argparse.Namespace) -> None:
  from softbench import zoo
  from softbench.runners import zoo_verification

  zoo_verification.verify_zoo(
    pathlib.Path(args.results),
    zoo.chosen_folder(args.zoo),
    tuple(args.agents) if args.agents else None,
    args.quick,
  )


_FAULT_HELP = (
  "a faulty actuator, MODULE:ACTUATOR:GAIN (module from 1, actuator from 0 within "
  "the module: cable xpos, ypos, xneg, yneg of a tendon arm, bellows 0.. (MJCF "
  "bellows1..) of the pneumatic arm; gain in [0, 1], 0 punctured); repeat for "
  "several"
)


class _OneLineErrorParser(argparse.ArgumentParser):
  """An argument parser (and, through ``add_subparsers``, its subcommands' parsers) whose
  command-line errors are one line, pointing at the command's own ``--help`` (and at the option
  meant, for a misspelt one) instead of printing the usage. Options are never abbreviated: run's
  ``--seeds N`` (a count) must not answer to render's ``--seed K`` (which seed)."""

  def __init__(self, *args, **kwargs):
    super().__init__(*args, allow_abbrev=False, **kwargs)
    self.command_parsers: dict[str, "_OneLineErrorParser"] = {}

  def error(self, message: str):
    self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

  def parse_args(self, args=None, namespace=None):
    """Parses like ``argparse``, but an argument no parser took is the command's error."""
    parsed, unknown = self.parse_known_args(args, namespace)
    if unknown:
      command = self.command_parsers.get(getattr(parsed, "command", None), self)
      command.error(f"unrecognized arguments: {' '.join(unknown)}{command.suggestion(unknown)}")
    return parsed

  def suggestion(self, unknown: list[str]) -> str:
    """'; did you mean --seeds?' for the first unknown option close to one of this parser's."""
    known = [option for action in self._actions for option in action.option_strings]
    for word in unknown:
      close = difflib.get_close_matches(word.partition("=")[0], known, n=1, cutoff=0.75)
      if word.startswith("--") and close:
        return f"; did you mean {close[0]}?"
    return ""


def _robots_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument("name", nargs="?", help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument("--module-length", type=float, help="module length in m")
  parser.add_argument("--json", action="store_true", help=_JSON_HELP)


def _tasks_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument("--json", action="store_true", help=_JSON_HELP)


def _collect_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import data

  parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument(
    "--samples",
    type=int,
    default=data.DEFAULT_SAMPLES,
    help=f"control periods to record (default {data.DEFAULT_SAMPLES})",
  )
  parser.add_argument("--seed", type=int, default=0, help="seed of the random actions")
  parser.add_argument(
    "--workers", type=int, default=None, help="simulation threads (default: every core)"
  )


def _agents_arguments(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--verbose", action="store_true", help="also show each learned agent's hyperparameters"
  )
  parser.add_argument("--json", action="store_true", help=_JSON_HELP + ", hyperparameters included")


def _tune_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import tuning

  parser.add_argument("--agent", required=True, help="a learned agent, e.g. smpl or lstm")
  parser.add_argument("--robot", required=True, help="e.g. tendon-3 or pneumatic-433")
  parser.add_argument(
    "--trials",
    type=int,
    default=tuning.DEFAULT_TRIALS,
    help=f"finished trials the study should hold, at most {tuning.MAX_TRIALS:,} (default "
    f"{tuning.DEFAULT_TRIALS}); re-running adds the missing ones",
  )
  parser.add_argument(
    "--storage", help="Optuna storage URL (default: sqlite:///$SOFTBENCH_HOME/tuning.db)"
  )
  parser.add_argument(
    "--profile",
    default=profiles.DEFAULT_PROFILE,
    help=f"data and epoch budget: one of {', '.join(profiles.PROFILES)} "
    f"(default {profiles.DEFAULT_PROFILE})",
  )
  parser.add_argument(
    "--epochs",
    type=int,
    help="epoch budget of each trial's inverse model (default: the "
    "profile's; fewer buys more trials)",
  )
  parser.add_argument("--study", help="study name (default AGENT-ROBOT-PROFILE)")
  parser.add_argument(
    "--summary", help="where to write the study summary (default $SOFTBENCH_HOME/tuning/STUDY.json)"
  )
  parser.add_argument(
    "--confirm",
    action="store_true",
    help="then train the previous and the best values at the profile's "
    "full epoch budget and report both",
  )
  parser.add_argument(
    "--adopt",
    action="store_true",
    help="commit the best values as the agent's hyperparameters on the "
    "robot (softbench/agents/hyperparameters.json)",
  )


def _run_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import robots
  from softbench import suite
  from softbench.records import exp1s as exp1s_records
  from softbench.runners import adaptive

  parser.add_argument("--task", help=f"one of {', '.join(suite.TASKS)}")
  parser.add_argument(
    "--protocol",
    help=f"{exp1s_records.PROTOCOL}: SMPL learns tendon-1 .. "
    f"tendon-5 (or another --family's arms) in sequence; "
    f"prints the paper's Exp1S table and the forgetting "
    f"matrix",
  )
  parser.add_argument(
    "--family",
    help=f"with --protocol {exp1s_records.PROTOCOL}: the tendon "
    f"family whose arms 1 .. 5 SMPL learns, one of "
    f"{', '.join(robots.TENDON_FAMILIES)} (default "
    f"{exp1s_records.DEFAULT_FAMILY})",
  )
  parser.add_argument("--agent", required=True, help=f"one of {', '.join(agents.AGENTS)}")
  parser.add_argument(
    "--robot", help="default: the task's robot in the paper (tendon-3; pneumatic-433 for reach)"
  )
  parser.add_argument("--seeds", type=int, help=_SEEDS_HELP)
  parser.add_argument(
    "--workers",
    type=int,
    help="processes that run seeds in parallel (default: one per core, at "
    "most one per seed); more than the cores keeps them all busy "
    "while the last seeds run, e.g. 3 for 5 seeds on 2 cores",
  )
  _add_profile_argument(parser)
  _add_eval_argument(parser)
  parser.add_argument("--trajectory", help="target poses for --task custom (.npy or .csv)")
  parser.add_argument(
    "--given",
    help="the part of every module's pose the --trajectory file gives: MODULES[:position], "
    "e.g. 3:position (module 3's position only) or 1,3 (modules 1 and 3, whole poses); "
    "a learned agent completes the rest (default: every module's whole pose)",
  )
  parser.add_argument(
    "--module", type=int, help="the module that reaches (--task reach; default 2)"
  )
  parser.add_argument(
    "--adaptive",
    action="store_true",
    help="--task reach with adaptive module activation: the reaching "
    "module alone, then its neighbours while they lower the error",
  )
  parser.add_argument(
    "--targets",
    type=int,
    help=f"virtual targets of --adaptive, at most {adaptive.MAX_TARGETS:,} "
    f"(default {adaptive.DEFAULT_TARGETS})",
  )
  parser.add_argument(
    "--helpers",
    help="how a learned agent completes a partial target (reach, --adaptive): "
    "complete (default; nearest babbling pose refined through its forward models, "
    "corrected from the measured error), nearest (the nearest babbling pose), "
    "hold (every other module at its starting pose) or share (the reaching module's error)",
  )
  _add_record_arguments(parser)
  parser.add_argument("--video", help="also render seed 0's episode to this .mp4 file")
  _add_video_arguments(parser)
  parser.add_argument(
    "--fault",
    action="append",
    default=[],
    help=_FAULT_HELP + "; the agent is trained on the healthy robot",
  )


def _sweep_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import robots
  from softbench import suite
  from softbench.records import exp1s as exp1s_records

  parser.add_argument(
    "--robots", nargs="+", default=[], metavar="ROBOT", help="e.g. tendon-1 tendon-3"
  )
  parser.add_argument(
    "--tasks", nargs="+", default=[], metavar="TASK", help=f"of {', '.join(suite.TASKS)}"
  )
  parser.add_argument(
    "--agents", nargs="+", default=[], metavar="AGENT", help=f"of {', '.join(agents.AGENTS)}"
  )
  parser.add_argument(
    "--protocol",
    help=f"{exp1s_records.PROTOCOL}: also SMPL's Exp1S on each of --families (then --robots, "
    "--tasks and --agents may be left out)",
  )
  parser.add_argument(
    "--families",
    nargs="+",
    metavar="FAMILY",
    help=f"with --protocol {exp1s_records.PROTOCOL}: of {', '.join(robots.TENDON_FAMILIES)} "
    f"(default {exp1s_records.DEFAULT_FAMILY})",
  )
  _add_profile_argument(parser)
  parser.add_argument("--seeds", type=int, help=_SEEDS_HELP)
  parser.add_argument(
    "--eval",
    nargs="+",
    default=["physics"],
    metavar="MODE",
    help="the error fed back: physics (default), model, open-loop; several: a setting each",
  )
  parser.add_argument(
    "--address",
    help="HOST:PORT of a Ray cluster's head (ray start --head); default: a local Ray",
  )
  parser.add_argument(
    "--data-home",
    help="the data home of this machine and every worker, e.g. on shared storage "
    "(default: $SOFTBENCH_HOME)",
  )
  _add_results_argument(parser)
  _add_physics_argument(parser)
  parser.add_argument(
    "--dry-run",
    action="store_true",
    help="print the settings that have no record yet and what they need built; run nothing",
  )


def _leaderboard_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import leaderboard
  from softbench.leaderboard import grid

  _add_results_argument(parser)
  parser.add_argument(
    "--write",
    action="store_true",
    help="also regenerate README.md and index.html in --out, and the "
    "results tables of the checkout's README.md and docs/*.md",
  )
  parser.add_argument(
    "--out",
    default=str(leaderboard.DEFAULT_OUT),
    help=f"folder of the pages (default {leaderboard.DEFAULT_OUT})",
  )
  parser.add_argument(
    "--grid",
    choices=tuple(grid.lists()),
    help="print the names on one axis of the grid make leaderboard fills, and nothing else",
  )
  for axis, metavar, what, example in (
    ("robots", "ROBOT", "robots", "tendon-3"),
    ("tasks", "TASK", "tasks", "reach"),
    ("agents", "AGENT", "agents", "smpl lstm"),
    ("profiles", "PROFILE", "profiles", "paper"),
    ("physics", "VERSION", "physics versions", "v0"),
  ):
    parser.add_argument(
      f"--{axis}",
      nargs="+",
      metavar=metavar,
      help=f"print only the records of these {what}, e.g. {example}",
    )


def _render_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import suite

  parser.add_argument("--task", required=True, help=f"one of {', '.join(suite.TASKS)}")
  parser.add_argument("--agent", required=True, help=f"one of {', '.join(agents.AGENTS)}")
  parser.add_argument("--robot", help="default: the task's robot in the paper")
  parser.add_argument("--out", required=True, help="the video file (.mp4)")
  parser.add_argument("--seed", default="0", help="agent and environment seed (default 0)")
  _add_profile_argument(parser)
  _add_eval_argument(parser)
  parser.add_argument("--trajectory", help="target poses for --task custom (.npy or .csv)")
  parser.add_argument(
    "--given", help="the part of every module's pose the --trajectory file gives (as for run)"
  )
  _add_video_arguments(parser)


def _retrain_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench.runners import retrain as retrain_module

  parser.add_argument(
    "--agent",
    default=retrain_module.RETRAINED_AGENT,
    help="the agent to adapt (smpl, the default, is the only one)",
  )
  parser.add_argument("--robot", help="default: the task's robot in the paper")
  parser.add_argument(
    "--fault", action="append", default=[], help=_FAULT_HELP + "; every fault in one module"
  )
  parser.add_argument(
    "--task", default=retrain_module.DEFAULT_TASK, help=f"default {retrain_module.DEFAULT_TASK}"
  )
  parser.add_argument(
    "--baseline",
    default=retrain_module.DEFAULT_BASELINE,
    help=f"centralised baseline retrained from scratch (default {retrain_module.DEFAULT_BASELINE})",
  )
  parser.add_argument("--seeds", type=int, help=_SEEDS_HELP)
  _add_profile_argument(parser)
  _add_record_arguments(parser)


def _add_zoo_setting_arguments(parser: argparse.ArgumentParser) -> None:
  """The setting of ``zoo add`` and ``zoo remove``: an agent on a robot, or Exp1S on a family."""
  from softbench import robots
  from softbench.records import exp1s as exp1s_records

  parser.add_argument("--agent", help="a learned agent")
  parser.add_argument("--robot", help="the robot it was trained on")
  parser.add_argument("--protocol", help=f"{exp1s_records.PROTOCOL}: the Exp1S networks instead")
  parser.add_argument(
    "--family",
    help=f"with --protocol {exp1s_records.PROTOCOL}: one of {', '.join(robots.TENDON_FAMILIES)}",
  )
  parser.add_argument(
    "--seeds",
    type=int,
    help=f"seeds 0 .. N-1, N at most {profiles.MAX_SEEDS:,} (default: the profile's)",
  )
  parser.add_argument(
    "--seed",
    type=int,
    action="append",
    default=[],
    help="seed K alone instead (repeat for several): e.g. to carry some trainings under way "
    "within the zoo's budget",
  )
  _add_profile_argument(parser)


def _zoo_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import zoo

  zoo_commands = parser.add_subparsers(dest="zoo_command", required=True)
  zoo_help = f"the zoo folder (default ${zoo.VARIABLE}, else zoo/ of the checkout)"
  list_parser = zoo_commands.add_parser("list", help="the zoo's files, sizes and records")
  list_parser.add_argument("--zoo", help=zoo_help)
  list_parser.set_defaults(run=_zoo_list)
  add_parser = zoo_commands.add_parser(
    "add",
    help="copy a setting's trained weights (or unfinished training) into the zoo",
    description="Copies each seed's checkpoint and forward models from the data home into the "
    "zoo, or the saved state of a training still under way, and links the records "
    "in --results that they made: those whose weights section names these files' sha256.",
  )
  _add_zoo_setting_arguments(add_parser)
  _add_results_argument(add_parser, "folder of the records to link")
  add_parser.add_argument(
    "--link-unchecked",
    action="store_true",
    help="also link the setting's records that name no weights (made before records named "
    "them); check them with softbench zoo verify",
  )
  add_parser.add_argument("--zoo", help=zoo_help)
  add_parser.set_defaults(run=_zoo_add)
  remove_parser = zoo_commands.add_parser(
    "remove",
    help="remove a setting's weights (or unfinished training) from the zoo",
    description="Removes each seed's checkpoint, or the saved state of its unfinished "
    "training, and the forward models that no other agent in the zoo reads.",
  )
  _add_zoo_setting_arguments(remove_parser)
  remove_parser.add_argument("--zoo", help=zoo_help)
  remove_parser.set_defaults(run=_zoo_remove)
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
  _add_results_argument(verify_parser, "folder of the records to verify")
  verify_parser.add_argument("--zoo", help=zoo_help)
  verify_parser.set_defaults(run=_zoo_verify)


def _models_arguments(parser: argparse.ArgumentParser) -> None:
  models_commands = parser.add_subparsers(dest="models_command", required=True)
  export_parser = models_commands.add_parser("export", help="write models/<name>/ for every robot")
  export_parser.add_argument("--out", default="models", help="output folder (default: models)")
  export_parser.add_argument(
    "--robots",
    nargs="+",
    metavar="ROBOT",
    help="export only these robots (default: every registered robot)",
  )
  export_parser.add_argument(
    "--measure-speed", action="store_true", help="also measure simulation speed into speed.json"
  )
  export_parser.set_defaults(run=_models_export)


@dataclasses.dataclass(frozen=True)
class _Command:
  """A command: its line in ``softbench --help``, the function that adds its arguments (and
  imports what their help names), the handler that runs it (None where its own subcommands
  name theirs) and its description in ``softbench COMMAND --help``."""

  help: str
  add_arguments: Callable[[argparse.ArgumentParser], None]
  run: Callable[[argparse.Namespace], None] | None
  description: str | None = None


_COMMANDS = {
  "robots": _Command("list the registered robots or describe one", _robots_arguments, _robots),
  "tasks": _Command("list the tasks of the suite", _tasks_arguments, _tasks),
  "collect": _Command(
    "record (or resume) a motor-babbling dataset",
    _collect_arguments,
    _collect,
    "Motor babbling with every module active, cached under $SOFTBENCH_HOME "
    "(default $XDG_CACHE_HOME/softbench, or ~/.cache/softbench); an interrupted "
    "collection resumes.",
  ),
  "agents": _Command("list the agents", _agents_arguments, _agents),
  "tune": _Command(
    "tune a learned agent's hyperparameters with Optuna",
    _tune_arguments,
    _tune,
    "Runs (or resumes) an Optuna study of the agent's hyperparameters on the "
    "babbling validation split; the same budget for every agent.",
  ),
  "run": _Command(
    "train (or reuse) an agent and score it on a task over seeds",
    _run_arguments,
    _run,
    "Collects or reuses the babbling dataset, trains or reuses the agent (cached "
    "by config), evaluates it (closed loop in physics unless --eval says otherwise) "
    "and prints the errors over seeds.",
  ),
  "sweep": _Command(
    "run a grid of robots, tasks and agents (and Exp1S) as Ray tasks, here or on a cluster",
    _sweep_arguments,
    _sweep,
    "Runs every setting (robot, task, agent, eval mode; with --protocol exp1s, "
    "Exp1S on each of --families) that --results has no record of for the profile, as Ray "
    "tasks: each babbling dataset, forward model, agent and Exp1S network is built once and "
    "shared, and each record is the one softbench run writes. Without --address, on a local "
    "Ray with one worker per core; docs/sweep.md for a cluster.",
  ),
  "leaderboard": _Command(
    "rank the result records per robot and task",
    _leaderboard_arguments,
    _leaderboard,
    "Checks every result record (schema and integrity hash) and prints, per robot "
    "and task, the newest record of each agent, profile and eval mode, ranked by "
    "position error: mean ± std over seeds [95% bootstrap CI].",
  ),
  "render": _Command(
    "render an agent's episode of a task to an MP4 video",
    _render_arguments,
    _render,
    "Trains (or reuses) the agent for one seed, runs its episode and renders it "
    "off-screen (the MUJOCO_GL you set, else egl, else osmesa) with the target "
    "trail and the achieved tip path.",
  ),
  "retrain": _Command(
    "retrain the faulty module's SMPL column after an actuator fault",
    _retrain_arguments,
    _retrain,
    "Collects babbling on the faulty robot, retrains only the faulty module's "
    "column of the smpl agent (and the forward models from that module on), and "
    "compares the errors before the fault, under it, after retraining one column "
    "and of a centralised baseline retrained from scratch, with wall times.",
  ),
  "zoo": _Command(
    "trained weights kept in the repository: list, add, verify",
    _zoo_arguments,
    None,
    "The zoo holds the weights behind leaderboard records (and the saved state of "
    "unfinished trainings); softbench run takes them instead of training.",
  ),
  "models": _Command("exported MJCF models", _models_arguments, None),
}


def build_parser(commands: Collection[str] = tuple(_COMMANDS)) -> argparse.ArgumentParser:
  """The command line's parser, with the arguments of ``commands`` (default: every command's;
  the others keep their line in ``softbench --help``, and their modules stay unimported)."""
  parser = _OneLineErrorParser(prog="softbench", description=__doc__.split(".")[0] + ".")
  parser.add_argument("--version", action="version", version=f"softbench {softbench.__version__}")
  subparsers = parser.add_subparsers(dest="command", required=True)
  for name, entry in _COMMANDS.items():
    command_parser = subparsers.add_parser(name, help=entry.help, description=entry.description)
    parser.command_parsers[name] = command_parser
    if name in commands:
      entry.add_arguments(command_parser)
      if entry.run is not None:
        command_parser.set_defaults(run=entry.run)
  return parser


def _command_named(argv: list[str]) -> str | None:
  """The command ``argv`` names: its first word that is not an option (softbench's own options,
  ``--help`` and ``--version``, take no value)."""
  return next((word for word in argv if not word.startswith("-")), None)


_CACHING_COMMANDS = ("collect", "run", "render", "retrain", "tune")  # They write to the data home.
_ZOO_COMMANDS = ("run", "render", "retrain", "sweep")  # They take trained weights from the zoo.
# Errors of a command's modules, as "module:class", that end it with one line: a bad input
# (EXIT_USAGE, as ValueError does), and a run that failed (EXIT_FAILURE).
_USAGE_ERRORS = ("softbench.rendering.video:RenderingUnavailable",)
_RUN_FAILURES = (
  "softbench.runners.parallel_seeds:WorkerDied",
  "softbench.rendering.video:RenderingFailed",
  "softbench.runners.continual:ForgettingDetected",
  "softbench.runners.zoo_verification:ZooMismatch",
  "softbench.sweep:SweepFailed",
)


_RUN_COMPLETE = (
  "softbench.runners.saving:RunComplete",
)  # An interrupt once the record was written.


def _imported_classes(names: tuple[str, ...]) -> tuple[type[BaseException], ...]:
  """The classes ``names`` ("module:class") of the modules imported so far. An error of a module
  never imported cannot have been raised, so catching only these loads nothing more."""
  found = []
  for entry in names:
    module_name, _, class_name = entry.partition(":")
    module = sys.modules.get(module_name)  # None where not imported: it has no such class.
    if hasattr(module, class_name):
      found.append(getattr(module, class_name))
  return tuple(found)


def _warn_of_left_out_agents() -> None:
  """A one-line warning per agent of an installed package that could not be registered, where
  this command loaded the registry (``agents.LEFT_OUT``)."""
  registry = sys.modules.get("softbench.agents")
  for message in getattr(registry, "LEFT_OUT", {}).values():
    warnings.warn(message, RuntimeWarning, stacklevel=1)


def main(argv: list[str] | None = None) -> int:
  argv = sys.argv[1:] if argv is None else argv
  try:
    named = _command_named(argv)
    args = build_parser([named] if named else []).parse_args(argv)
  except SystemExit as done:  # --help (0), or a malformed command line (one line, 2).
    return done.code
  terminal.one_line_warnings()
  _warn_of_left_out_agents()
  try:
    with terminal.sigterm_as_interrupt():
      if args.command in _CACHING_COMMANDS:  # Before any work: a home that takes no file fails
        storage.check_home()  # at once, not after the first seed.
      if args.command in _ZOO_COMMANDS:
        zoo.folder()  # A $SOFTBENCH_ZOO that names no folder: refused before any work.
      args.run(args)
  except (
    ValueError,
    FileNotFoundError,
    FloatingPointError,
    *_imported_classes(_USAGE_ERRORS),
  ) as error:
    print(f"softbench: error: {storage.first_line(error)}", file=sys.stderr)
    return EXIT_USAGE
  except _imported_classes(_RUN_FAILURES) as error:
    print(f"softbench: error: {storage.first_line(error)}", file=sys.stderr)
    return EXIT_FAILURE
  except control.PhysicsError as error:  # MuJoCo's state blew up during an episode.
    print(
      f"softbench: error: the simulation became unstable ({storage.first_line(error)})",
      file=sys.stderr,
    )
    return EXIT_FAILURE
  except _imported_classes(_RUN_COMPLETE) as complete:
    print(
      f"softbench: interrupted once the run was complete: its result record is {complete.path}"
      " (what follows the record, a copy, plots or a video, may be missing)",
      file=sys.stderr,
    )
    return EXIT_INTERRUPTED
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
    return storage.first_line(error)
  target = f" -> {error.filename2}" if error.filename2 is not None else ""
  return f"{error.filename}{target}: {error.strerror}"


if __name__ == "__main__":
  sys.exit(main())
