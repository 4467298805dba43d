"""One code style for the whole repository, kept by ruff as pyproject.toml configures it: the
formatter leaves every file as it is, and the linter (pycodestyle, pyflakes, import order) finds
nothing."""

import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("command", [["format", "--check"], ["check"]], ids=["format", "lint"])
def test_the_code_keeps_its_style(command):
  result = subprocess.run(
    [sys.executable, "-m", "ruff", *command, "."], cwd=ROOT, capture_output=True, text=True
  )
  assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize(
  "command,source",
  [
    (["format", "--check"], "def f():\n    return 1\n"),  # 4-space indentation
    (["check"], "import os\n"),  # an unused import
  ],
  ids=["format", "lint"],
)
def test_the_style_check_finds_a_deviation(command, source):
  result = subprocess.run(
    [sys.executable, "-m", "ruff", *command, "--stdin-filename", "softbench/example.py", "-"],
    cwd=ROOT,
    input=source,
    capture_output=True,
    text=True,
  )
  assert result.returncode != 0
