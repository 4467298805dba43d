"""``softbench render``: an agent's episode of a task rendered to an MP4 video."""

import argparse

from softbench.cli import arguments
from softbench.cli.command import Command


def add_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import agents
  from softbench import suite

  parser.add_argument("--task", required=True, help=f"one of {', '.join(suite.TASKS)}")
  parser.add_argument("--agent", required=True, help=f"one of {', '.join(agents.AGENTS)}")
  parser.add_argument("--robot", help="default: the task's robot in the paper")
  parser.add_argument("--out", required=True, help="the video file (.mp4)")
  parser.add_argument("--seed", default="0", help="agent and environment seed (default 0)")
  arguments.add_profile_argument(parser)
  arguments.add_eval_argument(parser)
  parser.add_argument("--trajectory", help="target poses for --task custom (.npy or .csv)")
  parser.add_argument(
    "--given", help="the part of every module's pose the --trajectory file gives (as for run)"
  )
  arguments.add_video_arguments(parser)


def handle(args: argparse.Namespace) -> None:
  from softbench.data import seeding
  from softbench.rendering import options as video_options
  from softbench.runners import run as run_module
  from softbench.runners import run_settings

  request = arguments.video_request(args, args.out)
  seed = video_options.parse_number("seed", args.seed, int)
  seeding.check_seed(seed)
  settings = run_settings.settings(
    args.task, args.agent, args.robot, 1, args.profile, args.eval, args.trajectory, given=args.given
  )
  run_module.render_seed(settings, seed, request)


COMMAND = Command(
  "render",
  "render an agent's episode of a task to an MP4 video",
  add_arguments,
  handle,
  "Trains (or reuses) the agent for one seed, runs its episode and renders it "
  "off-screen (the MUJOCO_GL you set, else egl, else osmesa) with the target "
  "trail and the achieved tip path.",
  caches=True,
  uses_zoo=True,
)
