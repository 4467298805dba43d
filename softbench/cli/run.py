"""``softbench run``: an agent scored on a task over seeds, ``--protocol exp1s``, or ``--protocol
continual``: a continual strategy learning a stream."""

import argparse
import pathlib

from softbench.cli import arguments
from softbench.cli.command import Command

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


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import robots
  from softbench import suite
  from softbench.continual import strategies
  from softbench.continual import streams
  from softbench.records import continual as continual_records
  from softbench.records import exp1s as exp1s_records
  from softbench.runners import adaptive

  parser.add_argument("--task", help=f"one of {', '.join(suite.TASKS)}")
  parser.add_argument(
    "--protocol",
    help=f"{exp1s_records.PROTOCOL}: SMPL learns tendon-1 .. "
    f"tendon-5 (or another --family's arms) in sequence; "
    f"prints the paper's Exp1S table and the forgetting "
    f"matrix. {continual_records.PROTOCOL}: the continual strategy --agent learns --stream "
    f"stage by stage; prints the error matrix, forgetting and each stage's training",
  )
  parser.add_argument(
    "--stream",
    help=f"with --protocol {continual_records.PROTOCOL}: one of {', '.join(streams.STREAMS)}",
  )
  parser.add_argument(
    "--family",
    help=f"with --protocol {exp1s_records.PROTOCOL} or {continual_records.PROTOCOL}: the tendon "
    f"family of the arms, one of "
    f"{', '.join(robots.TENDON_FAMILY_NAMES)} (default "
    f"{exp1s_records.DEFAULT_FAMILY})",
  )
  parser.add_argument(
    "--agent",
    required=True,
    help=f"one of {', '.join(agents.AGENTS)}; with --protocol {continual_records.PROTOCOL}, "
    f"a strategy: {', '.join(strategies.STRATEGIES)}",
  )
  parser.add_argument(
    "--robot", help="default: the task's robot in the paper (tendon-3; pneumatic-433 for reach)"
  )
  parser.add_argument("--seeds", type=int, help=arguments.SEEDS_HELP)
  parser.add_argument(
    "--workers",
    type=int,
    help="processes that run seeds in parallel (default: one per core, at "
    "most one per seed); more than the cores keeps them all busy "
    "while the last seeds run, e.g. 3 for 5 seeds on 2 cores",
  )
  arguments.add_profile_argument(parser)
  arguments.add_eval_argument(parser)
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
  arguments.add_record_arguments(parser)
  parser.add_argument("--video", help="also render seed 0's episode to this .mp4 file")
  arguments.add_video_arguments(parser)
  parser.add_argument(
    "--fault",
    action="append",
    default=[],
    help=arguments.FAULT_HELP + "; the agent is trained on the healthy robot",
  )


def handle(args: argparse.Namespace) -> None:
  from softbench.data import dataset
  from softbench.runners import run as run_module
  from softbench.runners import run_settings
  from softbench.runners import saving

  video_flags = arguments.flags_given(args, arguments.VIDEO_OPTIONS)
  if args.video is None and video_flags:
    raise ValueError(
      f"{', '.join(video_flags)} {'goes' if len(video_flags) == 1 else 'go'} with --video FILE.mp4"
    )
  arguments.check_record_arguments(args)
  if args.workers is not None:  # Before any collection or training starts.
    dataset.check_count("workers", args.workers)
  if args.protocol is not None:
    return _run_protocol(args)
  if args.family is not None:
    raise ValueError("--family goes with --protocol exp1s or continual; a task's robot is --robot")
  if args.stream is not None:
    raise ValueError("--stream goes with --protocol continual")
  if args.task is None:
    raise ValueError("softbench run needs --task TASK (or --protocol exp1s)")
  settings = run_settings.settings(
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
  video_request = arguments.video_request(args, args.video) if args.video else None
  record, episodes = run_module.execute_episodes(settings, keep_seeds=True, workers=args.workers)
  saving.save(
    run_module,
    record,
    pathlib.Path(args.results),
    arguments.json_copy(args),
    lambda files: run_module.finish(settings, record, files, episodes, video_request),
  )


def _run_protocol(args: argparse.Namespace) -> None:
  from softbench.records import continual as continual_records
  from softbench.runners import continual
  from softbench.runners import saving

  if args.protocol == continual_records.PROTOCOL:
    return _run_stream(args)
  if args.stream is not None:
    raise ValueError(f"--stream goes with --protocol {continual_records.PROTOCOL}")
  settings = continual.settings(
    args.protocol,
    args.agent,
    args.profile,
    args.family,
    args.seeds,
    args.eval,
    arguments.flags_given(args, _TASK_RUN_OPTIONS),
  )
  record = continual.execute(
    settings.profile, settings.seeds, workers=args.workers, keep_seeds=True, family=settings.family
  )
  saving.save(
    continual,
    record,
    pathlib.Path(args.results),
    arguments.json_copy(args),
    lambda files: continual.finish(record, files),
  )


def _run_stream(args: argparse.Namespace) -> None:
  from softbench.runners import continual_stream
  from softbench.runners import saving

  settings = continual_stream.settings(
    args.agent,
    args.stream,
    args.profile,
    args.family,
    args.seeds,
    args.eval,
    arguments.flags_given(args, _TASK_RUN_OPTIONS),
  )
  record = continual_stream.execute(settings, workers=args.workers, keep_seeds=True)
  saving.save(
    continual_stream,
    record,
    pathlib.Path(args.results),
    arguments.json_copy(args),
    lambda files: continual_stream.finish(settings, record, files),
  )


COMMAND = Command(
  "run",
  "train (or reuse) an agent and score it on a task over seeds",
  add_arguments,
  handle,
  "Collects or reuses the babbling dataset, trains or reuses the agent (cached "
  "by config), evaluates it (closed loop in physics unless --eval says otherwise) "
  "and prints the errors over seeds.",
  caches=True,
  uses_zoo=True,
)
