"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

import ctypes.util
import os

# MuJoCo loads the OpenGL backend named by MUJOCO_GL when it is imported. Headless by default:
# EGL where its library is installed, else OSMesa; a user may still choose another.
_BACKENDS = (("egl", "EGL"), ("osmesa", "OSMesa"))  # (MUJOCO_GL value, shared library)
if "MUJOCO_GL" not in os.environ:
  for _backend, _library in _BACKENDS:
    if ctypes.util.find_library(_library):
      os.environ["MUJOCO_GL"] = _backend
      break

__version__ = "0.1.0"
