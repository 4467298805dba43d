"""The ``softbench`` console script: loads MuJoCo and dm_control's OpenGL backend first, so that
a backend that cannot load (``MUJOCO_GL``) is one line and exit code 2, then runs ``softbench.cli``.

Where softbench chose the backend itself (``MUJOCO_GL`` unset) and it fails to open, as EGL does
when its library is installed but no display can be created, the command starts again with the
next installed headless backend (OSMesa) before giving up.
"""

import os
import sys

import softbench

EXIT_USAGE = 2
# Set for a restart with a fallback backend: the backends that failed before, with their errors.
FAILED_BACKENDS_VARIABLE = "SOFTBENCH_FAILED_GL_BACKENDS"
INSTALL_HINT = "libegl1 and libgl1-mesa-dri for egl, libosmesa6 for osmesa"


def _fallback(failed: str) -> str | None:
  """The headless backend to try after the automatically chosen ``failed``, if any."""
  installed = softbench.installed_headless_backends()
  later = installed[installed.index(failed) + 1 :] if failed in installed else []
  return later[0] if later else None


def main(argv: list[str] | None = None) -> int:
  try:
    from dm_control import _render  # noqa: F401  (dm_control opens the backend on import.)
    import mujoco  # noqa: F401  (MuJoCo checks MUJOCO_GL on import.)
  except (ImportError, AttributeError, RuntimeError, OSError) as error:
    backend = os.environ.get("MUJOCO_GL")
    failures = [entry for entry in [os.environ.get(FAILED_BACKENDS_VARIABLE)] if entry]
    from smpl.files import first_line  # pylint: disable=import-outside-toplevel

    failures.append(f"MUJOCO_GL={backend!r}: {type(error).__name__}: {first_line(error)}")
    fallback = _fallback(backend) if softbench.AUTOMATIC_GL_BACKEND == backend else None
    if fallback is not None:
      environment = dict(
        os.environ, MUJOCO_GL=fallback, **{FAILED_BACKENDS_VARIABLE: "; ".join(failures)}
      )
      environment.pop("PYOPENGL_PLATFORM", None)  # dm_control sets it for the failed backend.
      arguments = sys.argv[1:] if argv is None else argv
      command = [sys.executable, "-m", "softbench.launcher", *arguments]
      os.execve(sys.executable, command, environment)
    print(
      f"softbench: error: MuJoCo cannot load an OpenGL backend ({'; '.join(failures)}); "
      f"unset MUJOCO_GL, or install what it needs ({INSTALL_HINT})",
      file=sys.stderr,
    )
    return EXIT_USAGE
  from softbench import cli

  return cli.main(argv)


if __name__ == "__main__":
  sys.exit(main())
