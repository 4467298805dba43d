"""Packaging: compatible ranges in the metadata, exact versions in the constraints file that the
README's commands install with, the licence and citation files, and the version."""

import pathlib
import re
import subprocess

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
