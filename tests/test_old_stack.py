"""The old stack, physics v0 (MuJoCo 3.17 with the cable plugin), end to end: CI runs this file in
``.venv-v0`` (``make smoke-v0``); on the current stack it is skipped.

One robot, one task, one agent, and a committed v0 record re-scored to the last digit.
"""

import json
import pathlib

import pytest

from softbench import cli
from softbench import records
from softbench import robots
from softbench.records import fields as record_fields
from softbench.robots import versions

pytestmark = pytest.mark.skipif(
  versions.current().name != "v0",
  reason=f"the old stack (physics v0) is not installed here: {versions.VERSIONS['v0'].install}",
)
COMMITTED = pathlib.Path(__file__).parents[1] / "leaderboard" / "results"
ZERO_CIRCLE = COMMITTED / "zero-tendon-3-circle-default-physics-2026-11-24T054247Z.json"


def test_the_tendon_arms_hang_on_the_cable_plugin():
  assert versions.cable_plugin_available()
  assert robots.make("tendon-3").backbone == "cable"
  assert "mujoco.elasticity.cable" in robots.make("tendon-3").to_xml()


def _record_written(folder: pathlib.Path) -> dict:
  (path,) = folder.glob("*.json")
  return records.read(path)


def test_a_run_writes_a_v0_record(tmp_path, capsys):
  argv = ["run", "--robot", "tendon-1", "--task", "circle", "--agent", "zero"]
  assert cli.main([*argv, "--profile", "tiny", "--seeds", "1", "--results", str(tmp_path)]) == 0
  record = _record_written(tmp_path)
  assert record_fields.physics_of(record) == "v0" and record[record_fields.PHYSICS_FIELD] == "v0"
  assert record["machine"]["mujoco"].startswith("3.")


def test_a_committed_v0_record_is_scored_again_to_the_last_digit(tmp_path, capsys):
  committed = json.loads(ZERO_CIRCLE.read_text())
  assert record_fields.physics_of(committed) == "v0"
  argv = ["run", "--robot", "tendon-3", "--task", "circle", "--agent", "zero"]
  assert cli.main([*argv, "--seeds", "1", "--results", str(tmp_path)]) == 0
  (seed,) = _record_written(tmp_path)["per_seed"]
  for metric in records.METRICS:
    assert seed[metric] == committed["per_seed"][0][metric], metric
