"""The ``softbench`` console script: loads MuJoCo first, so that an OpenGL backend it cannot load
(``MUJOCO_GL``) is one line and exit code 2, then runs ``softbench.cli``."""

import os
import sys

EXIT_USAGE = 2


def main(argv: list[str] | None = None) -> int:
  try:
    import mujoco  # noqa: F401  (MuJoCo loads the MUJOCO_GL backend on import.)
  except (ImportError, AttributeError, RuntimeError, OSError) as error:
    print(f"softbench: error: MuJoCo cannot load with MUJOCO_GL="
          f"{os.environ.get('MUJOCO_GL')!r} ({type(error).__name__}: {error}); unset MUJOCO_GL, "
          f"or install what it needs (libegl1 for egl, libosmesa6 for osmesa)", file=sys.stderr)
    return EXIT_USAGE
  from softbench import cli
  return cli.main(argv)


if __name__ == "__main__":
  sys.exit(main())
