"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

from collections.abc import Iterator
import ctypes.util
import os

# MuJoCo loads the OpenGL backend named by MUJOCO_GL when it is imported. Headless by default:
# EGL where its library is installed, else OSMesa; a user may still choose another.
HEADLESS_BACKENDS = (("egl", "EGL"), ("osmesa", "OSMesa"))  # (MUJOCO_GL value, shared library)


def _installed_headless_backends() -> Iterator[str]:
  """The headless backends whose shared library is installed, in order of preference, looked up
  one at a time (each look-up runs ldconfig: 1.5 to 10 ms here, with the cores busy)."""
  return (backend for backend, library in HEADLESS_BACKENDS if ctypes.util.find_library(library))


def installed_headless_backends() -> list[str]:
  """The headless backends whose shared library is installed, in order of preference."""
  return list(_installed_headless_backends())


# The backend softbench chose, or None where the user set MUJOCO_GL (or nothing is installed).
AUTOMATIC_GL_BACKEND = None
if "MUJOCO_GL" not in os.environ:
  AUTOMATIC_GL_BACKEND = next(_installed_headless_backends(), None)
  if AUTOMATIC_GL_BACKEND is not None:
    os.environ["MUJOCO_GL"] = AUTOMATIC_GL_BACKEND

__version__ = "0.1.0"
