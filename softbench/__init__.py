"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

import os

# Headless by default: softbench renders off-screen (EGL); a user may still choose another.
os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.1.0"
