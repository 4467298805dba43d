"""Packaging: compatible ranges in the metadata, exact versions in the constraints file that the
README's commands install with, the licence and citation files, the version, and native
libraries loaded in an order that works (triton before EGL)."""

import importlib.util
import os
import pathlib
import re
import subprocess
import sys

from packaging import requirements
from packaging import utils
import pytest
import tomllib

import softbench
from softbench import cli

ROOT = pathlib.Path(__file__).parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PYPROJECT_MUJOCO = next(
  requirement.specifier
  for requirement in map(requirements.Requirement, PYPROJECT["project"]["dependencies"])
  if requirement.name == "mujoco"
)


def _pins() -> dict[str, str]:
  """Package name (normalised) -> exact version, from constraints.txt."""
  pins = {}
  for line in (ROOT / "constraints.txt").read_text().splitlines():
    if line.strip() and not line.startswith("#"):
      name, version = line.split("==")
      pins[utils.canonicalize_name(name)] = version
  return pins


def _declared() -> list[requirements.Requirement]:
  project = PYPROJECT["project"]
  return [
    requirements.Requirement(text)
    for text in project["dependencies"] + sum(project["optional-dependencies"].values(), [])
  ]


def test_the_metadata_declares_ranges_not_exact_versions():
  for requirement in _declared():
    assert not any(spec.operator in ("==", "===") for spec in requirement.specifier), requirement
    assert any(spec.operator == "<" for spec in requirement.specifier), (
      f"{requirement} has no upper bound"
    )


def test_every_declared_dependency_is_pinned_within_its_range():
  pins = _pins()
  for requirement in _declared():
    name = utils.canonicalize_name(requirement.name)
    assert name in pins, f"{name} is not in constraints.txt"
    assert requirement.specifier.contains(pins[name]), f"{name}=={pins[name]} not in {requirement}"


@pytest.mark.parametrize(
  "stamp, constraints, mujoco",
  [
    (".venv/.installed", "constraints.txt", "4."),
    (".venv-v0/.installed", "constraints-v0.txt", "3.17."),
  ],
)
def test_each_stack_installs_with_its_constraints(stamp, constraints, mujoco):
  # The current stack (physics v1) for make run and make test; the old one (v0) for make run-v0.
  planned = subprocess.run(
    ["make", "-n", "-B", stamp], cwd=ROOT, capture_output=True, text=True, check=True
  ).stdout
  venv = stamp.split("/")[0]
  assert re.search(
    rf"{re.escape(venv)}/bin/pip install [^\n]*-c {constraints} -e '\.\[test\]'", planned
  )
  pins = dict(
    line.split("==")
    for line in (ROOT / constraints).read_text().splitlines()
    if "==" in line and not line.startswith("#")
  )
  assert pins["mujoco"].startswith(mujoco)
  assert PYPROJECT_MUJOCO.contains(pins["mujoco"])
  makefile = (ROOT / "Makefile").read_text()
  assert re.search(
    rf"^\$\(STAMP{'_V0' if 'v0' in venv else ''}\): pyproject\.toml {constraints}$", makefile, re.M
  )


def test_licence_citation_and_version_agree():
  assert "Apache License\n                           Version 2.0" in (ROOT / "LICENSE").read_text()
  assert PYPROJECT["project"]["license"] == "Apache-2.0"
  citation = (ROOT / "CITATION.cff").read_text()
  assert re.search(rf"^version: {re.escape(softbench.__version__)}$", citation, re.M)
  assert "Continual Learning Framework for Adaptive Control of Modular Soft Robots" in citation


def test_version_flag(capsys):
  assert cli.main(["--version"]) == 0
  assert capsys.readouterr().out == f"softbench {softbench.__version__}\n"


# A stand-in for triton's native library: it fails where Mesa's EGL is loaded already (dm_control
# loads it when imported with MUJOCO_GL=egl), where the real one crashes the process.
_FAKE_TRITON_LIBRARY = """
import sys
if "dm_control.mujoco" in sys.modules:
  raise SystemExit("triton loaded after EGL")
print("triton loaded first")
"""


@pytest.fixture
def fake_triton(tmp_path) -> dict:
  """The environment of a child process that finds a stand-in for triton and renders with EGL."""
  (tmp_path / "triton" / "_C").mkdir(parents=True)
  (tmp_path / "triton" / "__init__.py").write_text("")
  (tmp_path / "triton" / "_C" / "__init__.py").write_text("")
  (tmp_path / "triton" / "_C" / "libtriton.py").write_text(_FAKE_TRITON_LIBRARY)
  return {**os.environ, "MUJOCO_GL": "egl", "PYTHONPATH": str(tmp_path)}


@pytest.mark.parametrize("program", ["import softbench.suite", "import softbench.envs"])
def test_softbench_loads_triton_before_egl(program, fake_triton):
  child = [sys.executable, "-c", f"{program}; import dm_control.mujoco; import triton._C.libtriton"]
  result = subprocess.run(child, env=fake_triton, capture_output=True, text=True, timeout=120)
  assert result.returncode == 0 and result.stdout.count("triton loaded first") == 1, result


def test_dm_control_imported_first_is_one_warning_not_a_crash(fake_triton):
  child = [sys.executable, "-c", "import dm_control.mujoco; import softbench"]
  result = subprocess.run(child, env=fake_triton, capture_output=True, text=True, timeout=120)
  assert result.returncode == 0 and "triton loaded" not in result.stdout, result
  assert "loading triton now would crash the process" in result.stderr, result


@pytest.mark.skipif(
  importlib.util.find_spec("triton") is None,
  reason="triton is not installed: the CPU build of torch (constraints.txt) comes without it",
)
def test_the_real_triton_and_egl_live_in_one_process():
  # Without softbench's order: MUJOCO_GL=egl python -c "import dm_control.mujoco; import triton"
  # ends in SIGSEGV (triton 3.9.0, Mesa's EGL, 2026-12-06).
  child = [sys.executable, "-c", "import softbench.suite, dm_control.mujoco, triton, torch._dynamo"]
  environment = {**os.environ, "MUJOCO_GL": "egl"}
  result = subprocess.run(child, env=environment, capture_output=True, text=True, timeout=300)
  assert result.returncode == 0, result


def test_a_broken_triton_is_one_warning_not_a_failed_import(fake_triton, tmp_path):
  (tmp_path / "triton" / "_C" / "libtriton.py").write_text("raise ImportError('libcuda.so.1')\n")
  child = [sys.executable, "-c", "import softbench.suite; print('imported')"]
  result = subprocess.run(child, env=fake_triton, capture_output=True, text=True, timeout=120)
  assert result.returncode == 0 and result.stdout == "imported\n", result
  assert "triton is installed but cannot be loaded: libcuda.so.1" in result.stderr
