"""Arguments that several commands share: their flags, their help and their checks."""

import argparse
import pathlib

from softbench import profiles
from softbench import storage

JSON_HELP = "print JSON (for scripts) instead of a table"
SEEDS_HELP = f"number of seeds, at most {profiles.MAX_SEEDS:,} (default: the profile's)"
FAULT_HELP = (
  "a faulty actuator, MODULE:ACTUATOR:GAIN (module from 1, actuator from 0 within "
  "the module: cable xpos, ypos, xneg, yneg of a tendon arm, bellows 0.. (MJCF "
  "bellows1..) of the pneumatic arm; gain in [0, 1], 0 punctured); repeat for "
  "several"
)
# The video flags (``add_video_arguments``) by attribute: ``VideoOptions`` fields.
VIDEO_OPTIONS = ("width", "height", "fps", "camera", "frames_per_step")


def flags_given(args: argparse.Namespace, names: tuple[str, ...]) -> list[str]:
  """The flags among ``names`` (attributes of ``args``) that the command line set: not left at
  None, False (a switch) or [] (a repeatable flag)."""
  unset = lambda value: value is None or value is False or value == []
  return [f"--{name.replace('_', '-')}" for name in names if not unset(getattr(args, name))]


def add_profile_argument(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--profile",
    default=profiles.DEFAULT_PROFILE,
    help=f"one of {', '.join(profiles.PROFILES)} (default {profiles.DEFAULT_PROFILE})",
  )


def add_eval_argument(parser: argparse.ArgumentParser) -> None:
  parser.add_argument(
    "--eval", default="physics", help="physics (default), model or open-loop: the error fed back"
  )


def add_results_argument(
  parser: argparse.ArgumentParser, what: str = "folder of the result records"
) -> None:
  from softbench import records

  parser.add_argument(
    "--results",
    default=str(records.DEFAULT_FOLDER),
    help=f"{what} (default {records.DEFAULT_FOLDER}, the committed leaderboard's)",
  )


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
  from softbench import records

  parser.add_argument(
    "--results",
    help=f"folder to write the result record to (default $SOFTBENCH_HOME/"
    f"{records.USER_FOLDER_NAME}, your own runs; the committed leaderboard's is "
    f"{records.DEFAULT_FOLDER})",
  )
  parser.add_argument("--json", help="also write the result record to this file")
  add_physics_argument(parser)


def add_physics_argument(parser: argparse.ArgumentParser) -> None:
  from softbench.robots import versions

  parser.add_argument(
    "--physics",
    metavar="VERSION",
    help=f"the physics version to simulate, of {', '.join(versions.VERSIONS)} (default: the "
    f"installed one, {versions.current().name}); another is refused, saying how to install it",
  )


def add_video_arguments(parser: argparse.ArgumentParser) -> None:
  """The flags of ``VIDEO_OPTIONS``; left out, they are None (``from_text`` takes the default)."""
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


def video_request(args: argparse.Namespace, path: str):
  """A ``run.VideoRequest`` of the options the video flags give, to ``path``; both checked."""
  from softbench.rendering import options as video_options
  from softbench.runners import run as run_module

  options = video_options.from_text(**{name: getattr(args, name) for name in VIDEO_OPTIONS})
  return run_module.VideoRequest(video_options.check_video_path(path), options)


def check_physics(args: argparse.Namespace) -> None:
  """Refuses a ``--physics`` that is unknown or not the installed one (one line)."""
  from softbench.robots import versions

  if args.physics is not None:
    versions.check(args.physics)


def check_record_arguments(args: argparse.Namespace) -> None:
  """Refuses a ``--physics`` this installation does not run, and a ``--results`` or ``--json``
  that could not be written, before the run."""
  from softbench import records

  check_physics(args)
  if args.results is None:
    args.results = str(records.user_folder())
  storage.check_writable(args.results, "result records to", folder=True)
  if args.json:
    storage.check_writable(args.json, "result record")


def json_copy(args: argparse.Namespace) -> pathlib.Path | None:
  """The ``--json`` copy of the result record, if asked for."""
  return pathlib.Path(args.json) if args.json else None
