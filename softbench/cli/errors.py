"""How a command ends: its exit code, and one line on stderr for an error it raised."""

from collections.abc import Callable
import os
import sys

from dm_control.rl import control

from softbench import storage

EXIT_USAGE = 2
EXIT_FAILURE = 1  # The run itself failed (not the input).
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it.
# Errors of a command's modules, as "module:class", that end it with one line: a bad input
# (EXIT_USAGE, as ValueError does), and a run that failed (EXIT_FAILURE).
_USAGE_ERRORS = ("softbench.rendering.video:RenderingUnavailable",)
_RUN_FAILURES = (
  "softbench.runners.parallel_seeds:WorkerDied",
  "softbench.rendering.video:RenderingFailed",
  "softbench.runners.continual:ForgettingDetected",
  "softbench.runners.zoo_verification:ZooMismatch",
  "softbench.sweep:SweepFailed",
  "softbench.sweep.cluster:ClusterUnavailable",
)


# An interrupt once the record was written.
_RUN_COMPLETE = ("softbench.runners.saving:RunComplete",)


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


def exit_code(work: Callable[[], None]) -> int:
  """Runs ``work`` and returns the command's exit code: 0, or that of the error it raised, said
  in one line on stderr."""
  try:
    work()
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
