"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

import ctypes.util
import os

# MuJoCo loads the OpenGL backend named by MUJOCO_GL when it is imported. Headless by default:
# EGL where its library is installed, else OSMesa; a user may still choose another.
HEADLESS_BACKENDS = (("egl", "EGL"), ("osmesa", "OSMesa"))  # (MUJOCO_GL value, shared library)


def installed_headless_backends() -> list[str]:
  """The headless backends whose shared library is installed, in order of preference."""
  return [backend for backend, library in HEADLESS_BACKENDS if ctypes.util.find_library(library)]


# The backend softbench chose, or None where the user set MUJOCO_GL (or nothing is installed).
AUTOMATIC_GL_BACKEND = None
if "MUJOCO_GL" not in os.environ and installed_headless_backends():
  AUTOMATIC_GL_BACKEND = os.environ["MUJOCO_GL"] = installed_headless_backends()[0]

__version__ = "0.1.0"
