"""Provenance of a record: softbench's version, the git commit (``-dirty`` with local changes to
the code: ``SOURCE_PATHS``; new records in a results folder are not), the date, the physics
version (``softbench.robots.versions``) and the machine (platform, CPU model and widest vector
extension, cores, Python, MuJoCo, torch and the device it computed on)."""

import datetime
from importlib import metadata
import os
import pathlib
import platform
import subprocess

import softbench
from softbench.robots import versions

SOURCE_PATHS = ("softbench", "smpl", "pyproject.toml", "constraints.txt", "constraints-v0.txt")
"""What makes a checkout's code, relative to its root: a change there (tracked or not) makes the
commit ``-dirty``. Records written into ``leaderboard/results`` of a clean checkout, as a
long run's records are one by one, were marking every later record dirty."""


def git_commit(root: pathlib.Path = pathlib.Path(__file__).parents[2]) -> str | None:
  """The commit of the checkout at ``root``, ``-dirty`` if its code changed; None outside git."""
  try:
    commit = subprocess.run(
      ["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True, cwd=root
    ).stdout.strip()
    dirty = subprocess.run(
      ["git", "status", "--porcelain", "--", *SOURCE_PATHS],
      capture_output=True,
      text=True,
      check=True,
      cwd=root,
    ).stdout.strip()
  except (OSError, subprocess.CalledProcessError):
    return None
  return commit + ("-dirty" if dirty else "")


def _machine(device: str) -> dict:
  return {
    "platform": platform.platform(),
    "processor": _processor(),
    "cpu_count": os.cpu_count(),
    "python": platform.python_version(),
    "mujoco": metadata.version("mujoco"),
    "torch": metadata.version("torch"),
    "device": device,
  }


def _processor() -> str:
  """The CPU's model name where Linux tells it (``platform.processor()`` is empty there), else
  what ``platform`` knows; with ``avx512``/``avx2`` added where Linux lists those flags, since
  libraries that pick kernels by CPU (OpenBLAS, oneDNN) round differently with them."""
  try:
    cpuinfo = pathlib.Path("/proc/cpuinfo").read_text()
  except OSError:
    return platform.processor() or platform.machine()
  fields = dict(line.split(":", 1) for line in cpuinfo.splitlines() if ":" in line)
  fields = {key.strip(): value.strip() for key, value in fields.items()}
  name = fields.get("model name") or platform.processor() or platform.machine()
  flags = fields.get("flags", "").split()
  widest = next((kind for kind in ("avx512f", "avx2") if kind in flags), None)
  return f"{name} ({widest.removesuffix('f')})" if widest else name


def provenance(device: str) -> dict:
  """Where and with what a run ran on ``device`` (torch's, e.g. ``cpu``); taken when it starts
  (the code may change while it runs)."""
  return {
    "softbench_version": softbench.__version__,
    "git_commit": git_commit(),
    "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    "physics": versions.current().name,
    "machine": _machine(device),
  }


def date_stamp(record: dict) -> str:
  """The record's date as it appears in file names, e.g. 2026-11-24T013000Z."""
  return record["date"].replace(":", "").replace("+0000", "Z")
