"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

from collections.abc import Iterator
import ctypes.util
import importlib.util
import os
import sys
import warnings

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

# Triton (installed with CUDA builds of torch, which a plain `pip install` picks) bundles its own
# LLVM: loaded after Mesa's EGL, which dm_control.mujoco loads when imported, it crashes the
# process (SIGSEGV; `MUJOCO_GL=egl python -c "import dm_control.mujoco; import triton"`), and
# torch._dynamo imports it at the first training. Loaded first, both work (docs/install.md).
TRITON_LIBRARY = "triton._C.libtriton"


def load_triton_before_egl() -> bool:
  """Loads triton's native library now if it is installed and EGL is the backend, before
  dm_control loads EGL; True if it did. Where dm_control.mujoco came first, says in one line that
  triton cannot be loaded in this process any more."""
  if os.environ.get("MUJOCO_GL") != "egl" or importlib.util.find_spec("triton") is None:
    return False
  if "dm_control.mujoco" in sys.modules and "triton" not in sys.modules:
    warnings.warn(
      "dm_control.mujoco was imported before softbench with MUJOCO_GL=egl, and triton is "
      "installed: loading triton now would crash the process (torch loads it to compile); import "
      "softbench first, or install the CPU build of torch (docs/install.md)",
      RuntimeWarning,
      stacklevel=3,
    )
    return False
  try:
    importlib.import_module(TRITON_LIBRARY)
  except Exception as error:  # A broken triton must not break softbench; torch may fail later.
    message = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    warnings.warn(f"triton is installed but cannot be loaded: {message}", RuntimeWarning, 2)
    return False
  return True


load_triton_before_egl()

__version__ = "0.1.0"
