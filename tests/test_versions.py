"""Physics versions (``softbench.robots.versions``): what carries them, and bad input about them.

Every command that runs physics takes ``--physics`` and refuses a version it cannot run in one
line with exit 2; records, cache keys and the zoo's verification keep the versions apart.
"""

import hashlib
import json
import pathlib
import shutil

import mujoco
import pytest

from softbench import cli
from softbench import records
from softbench import robots
from softbench import zoo
from softbench.records import fields as record_fields
from softbench.records import provenance
from softbench.robots import versions

OTHER = next(name for name in versions.VERSIONS if name != versions.current().name)
CHECKOUT = pathlib.Path(__file__).parents[1]


def test_the_installed_mujoco_names_one_version():
  assert versions.engine_version() == mujoco.__version__  # Read from metadata, without MuJoCo.
  here = versions.current()
  assert here.engine_major == versions.engine_major()
  assert versions.cable_plugin_available() == (here.backbone == "cable")
  for family in (robots.family_named(name).arm for name in robots.TENDON_FAMILY_NAMES):
    assert family(num_modules=2).backbone == here.backbone


def test_a_record_says_its_physics_and_mujoco():
  origin = provenance.provenance("cpu")
  assert origin["physics"] == versions.current().name
  assert origin["machine"]["mujoco"] == versions.engine_version()


def test_a_record_without_physics_is_v0():
  assert record_fields.physics_of({"agent": "zero"}) == "v0"


@pytest.mark.parametrize("name", robots.REGISTERED_ROBOTS)
def test_cache_keys_name_the_physics(name):
  # v0 keeps the hash of the MJCF alone (the zoo's v0 files still answer there); later versions
  # add their name, so that the pneumatic arm, whose MJCF is the same on both, keys apart.
  arm = robots.make(name)
  own = hashlib.sha256(arm.to_xml().encode()).hexdigest()
  assert (arm.physics_sha256() == own) == (versions.current().name == versions.FIRST)


@pytest.mark.parametrize(
  "argv, message",
  [
    (["run", "--task", "spiral", "--agent", "zero", "--physics", "v9"], "unknown physics version"),
    (["run", "--task", "spiral", "--agent", "zero", "--physics", OTHER], f"physics {OTHER} "),
    (["sweep", "--robots", "tendon-1", "--dry-run", "--physics", OTHER], f"physics {OTHER} "),
    (["sweep", "--robots", "tendon-1", "--dry-run", "--physics", "V1"], "unknown physics version"),
    (["leaderboard", "--physics", "v9"], "unknown physics version 'v9'"),
  ],
)
def test_a_version_this_installation_cannot_run_is_one_line(argv, message, capsys, tmp_path):
  assert cli.main([*argv, "--results", str(tmp_path)]) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  lines = captured.err.strip().splitlines()
  assert len(lines) == 1 and lines[0].startswith("softbench: error: ") and message in lines[0]
  if message.startswith("physics"):
    assert versions.VERSIONS[OTHER].install in lines[0]  # Says how to get that stack.
  assert not any(tmp_path.iterdir())


def test_the_leaderboard_shows_one_version_when_asked(tmp_path, capsys):
  path, record = next(
    (path, record)
    for path, record in records.read_folder(CHECKOUT / records.DEFAULT_FOLDER)
    if record_fields.physics_of(record) == "v0"
  )
  (tmp_path / path.name).write_text(json.dumps(record))
  assert cli.main(["leaderboard", "--results", str(tmp_path), "--physics", "v0"]) == 0
  assert "1 result record(s) of physics v0" in capsys.readouterr().out
  assert cli.main(["leaderboard", "--results", str(tmp_path), "--physics", "v1"]) == 0
  assert capsys.readouterr().out.startswith("no result records of physics v1")


def test_the_cable_backbone_is_refused_where_mujoco_lacks_the_plugin():
  if versions.cable_plugin_available():
    assert "mujoco.elasticity.cable" in robots.make("tendon-2", backbone="cable").to_xml()
  else:
    with pytest.raises(ValueError, match="cable plugin"):
      robots.make("tendon-2", backbone="cable")


@pytest.mark.skipif(versions.current().name == "v0", reason="the zoo's records are v0: verifiable")
def test_zoo_verify_refuses_records_of_another_physics_in_one_line(tmp_path, capsys):
  # A zoo of one v0 checkpoint of the repository's zoo, and the committed records.
  repository = CHECKOUT / "zoo"
  entry = next(
    entry
    for entry in zoo.read_manifest(repository).values()
    if entry.kind == "agent" and entry.physics == "v0" and entry.records
  )
  (tmp_path / entry.path).parent.mkdir(parents=True)
  shutil.copy(repository / entry.path, tmp_path / entry.path)
  zoo.write_manifest(tmp_path, {entry.path: entry})
  argv = ["zoo", "verify", "--quick", "--zoo", str(tmp_path)]
  assert cli.main([*argv, "--results", str(CHECKOUT / records.DEFAULT_FOLDER)]) == cli.EXIT_USAGE
  (line,) = capsys.readouterr().err.strip().splitlines()
  assert "cannot be re-scored on physics" in line and versions.VERSIONS["v0"].install in line
