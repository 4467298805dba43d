"""The zoo: trained weights taken instead of training, refused when damaged, unfinished trainings
carried to another data home, and records re-scored from it (``softbench zoo``)."""

import json
import pathlib
import shutil

import numpy as np
import pytest

from smpl import fitting
from softbench import agents
from softbench import cli
from softbench import leaderboard
from softbench import profiles
from softbench import records
from softbench import suite
from softbench import zoo
from softbench.agents import learned
from softbench.data import dataset as data_files
from softbench.leaderboard import verified
from softbench.learning import checkpoints
from softbench.learning import protocols
from softbench.robots import versions
from softbench.runners import evaluation
from softbench.runners import zoo_catalogue as catalogue

LEARNED_AGENTS = agents.babbling_learners()  # The agents whose weights the zoo keeps.
CHECKOUT = pathlib.Path(__file__).resolve().parents[1]
ROBOT = "tendon-2"
TINY = profiles.get("tiny")


def actions(agent_name, seed=0):
  agent = agents.make(agent_name, ROBOT, seed, "tiny")
  return evaluation.run_episode(
    suite.load(ROBOT, "circle", seed=seed, length=4), agent, "circle"
  ).actions


def use(monkeypatch, home, zoo_folder=None, datasets=None):
  """Makes ``home`` the data home (with a copy of the ``datasets`` folder, if given) and
  ``zoo_folder`` the zoo (None: turned off)."""
  monkeypatch.setenv("SOFTBENCH_HOME", str(home))
  monkeypatch.setenv(zoo.VARIABLE, str(zoo_folder) if zoo_folder else zoo.OFF)
  if datasets is not None:
    shutil.copytree(datasets, home / data_files.DATASETS_FOLDER)


@pytest.fixture(scope="module")
def babbled(babbled_datasets):
  """``ROBOT``'s tiny babbling dataset, for the homes where a test trains; the homes that must
  not train or collect stay empty."""
  return babbled_datasets(ROBOT)


def no_training(monkeypatch):
  """Makes any training or babbling collection fail the test."""

  def refuse(*args, **kwargs):
    raise AssertionError("trained or collected although the zoo holds the weights")

  monkeypatch.setattr(fitting, "fit", refuse)
  monkeypatch.setattr(protocols, "prepare_column", refuse)
  monkeypatch.setattr(learned.data, "collect", refuse)


@pytest.fixture(scope="module")
def trained_zoos(tmp_path_factory, run_wide_homes):
  """Per learned agent (made on first use): a zoo of its tiny seed-0 weights, trained in the run's
  home of ROBOT (test_agents_and_run's ``TestEveryAgent`` trains the same), and the trained
  agent's actions."""
  made = {}

  def get(agent_name):
    if agent_name not in made:
      base = tmp_path_factory.mktemp(f"zoo-{agent_name}")
      with pytest.MonkeyPatch.context() as patched:
        use(patched, run_wide_homes(ROBOT))
        trained = actions(agent_name)
        chosen = catalogue.setting(agent_name, ROBOT, None, "tiny", 1)
        zoo.add([(path, kind) for _, path, kind in catalogue.cache_files(chosen)], {}, base / "zoo")
      made[agent_name] = (base / "zoo", trained)
    return made[agent_name]

  return get


def _without_reference_lines(err: str) -> list[str]:
  """``err``'s lines but those that say a reference is simulated (once per empty data home)."""
  return [line for line in err.splitlines() if not line.startswith("simulating ")]


@pytest.fixture
def zoo_of(trained_zoos, tmp_path):
  """A copy (the test's own) of ``agent_name``'s zoo, and the trained agent's actions."""

  def copy(agent_name):
    folder, trained = trained_zoos(agent_name)
    shutil.copytree(folder, tmp_path / "zoo")
    return tmp_path / "zoo", trained

  return copy


@pytest.mark.parametrize("agent_name", LEARNED_AGENTS)
def test_an_empty_data_home_takes_the_zoos_weights_instead_of_training(
  agent_name, zoo_of, tmp_path, monkeypatch, capsys
):
  folder, trained = zoo_of(agent_name)
  capsys.readouterr()
  use(monkeypatch, tmp_path / "empty", folder)
  with monkeypatch.context() as patched:
    no_training(patched)
    np.testing.assert_array_equal(actions(agent_name), trained)
  (line,) = _without_reference_lines(capsys.readouterr().err)
  assert line.startswith("softbench: zoo: took checkpoints/") and "instead of training" in line


def test_a_tampered_zoo_file_is_refused_in_one_line_and_the_agent_trained(
  zoo_of, babbled, tmp_path, monkeypatch
):
  # The zoo checks bytes, whatever the agent: one agent shows it.
  agent_name = "mlp"
  folder, trained = zoo_of(agent_name)
  (checkpoint,) = folder.glob(f"{checkpoints.CHECKPOINT_FOLDER}/{agent_name}-*.pt")
  content = bytearray(checkpoint.read_bytes())
  content[len(content) // 2] ^= 1  # One bit of the weights.
  checkpoint.write_bytes(bytes(content))
  use(monkeypatch, tmp_path / "untrained", folder, datasets=babbled)
  with pytest.warns(zoo.ZooWarning) as caught:
    retrained = actions(agent_name)
  (warning,) = [entry for entry in caught if issubclass(entry.category, zoo.ZooWarning)]
  message = str(warning.message)
  assert str(checkpoint) in message and "tampered" in message and "\n" not in message
  np.testing.assert_array_equal(retrained, trained)


@pytest.mark.parametrize(
  "damage",
  [
    "not json",
    '{"format": "softbench-zoo", "version": 1}',
    '{"format": "other", "version": 1, "entries": []}',
  ],
)
def test_a_damaged_manifest_is_refused_in_one_line(damage, tmp_path):
  (tmp_path / zoo.MANIFEST).write_text(damage)
  with pytest.raises(ValueError, match="unreadable zoo manifest") as raised:
    zoo.read_manifest(tmp_path)
  assert str(tmp_path / zoo.MANIFEST) in str(raised.value) and "\n" not in str(raised.value)


def test_an_unreadable_manifest_is_one_warning_and_the_agent_trains(
  zoo_of, babbled, tmp_path, monkeypatch
):
  folder, trained = zoo_of("mlp")
  (folder / zoo.MANIFEST).write_text("not json")
  use(monkeypatch, tmp_path / "empty", folder, datasets=babbled)
  with pytest.warns(zoo.ZooWarning, match="unreadable zoo manifest"):
    np.testing.assert_array_equal(actions("mlp"), trained)


def test_a_manifest_path_outside_the_zoo_is_refused(tmp_path):
  entry = zoo.ZooFile("../outside.pt", "0" * 64, 1, "agent", "outside")
  (tmp_path / zoo.MANIFEST).write_text(
    json.dumps({"format": zoo.FORMAT, "version": zoo.VERSION, "entries": [entry.to_json()]})
  )
  with pytest.raises(ValueError, match="outside the zoo"):
    zoo.read_manifest(tmp_path)


@pytest.mark.parametrize("agent_name", LEARNED_AGENTS)
def test_the_zoo_takes_no_unfinished_training(
  agent_name, interrupted_training, babbled, tmp_path, monkeypatch
):
  use(monkeypatch, tmp_path / "first", datasets=babbled)
  with interrupted_training():
    actions(agent_name)
  chosen = catalogue.setting(agent_name, ROBOT, None, "tiny", 1)
  files = [(path, kind) for _, path, kind in catalogue.cache_files(chosen)]
  unfinished = [path for path, _ in files if not path.exists()]
  assert any(checkpoints.snapshot_folder(path).is_dir() for path in unfinished)
  finished = [(path, kind) for path, kind in files if path.exists()]
  if not finished:
    with pytest.raises(ValueError, match="^nothing of this setting has finished training"):
      zoo.add(files, {}, tmp_path / "zoo")
    return
  added, skipped = zoo.add(files, {}, tmp_path / "zoo")
  assert skipped == unfinished
  assert sorted(entry.path for entry in added) == sorted(
    path.relative_to(tmp_path / "first").as_posix() for path, _ in finished
  )
  assert not list((tmp_path / "zoo").rglob("*.partial*"))


def test_the_zoo_refuses_to_outgrow_its_budget(babbled, zoo_of, tmp_path, monkeypatch):
  folder, _ = zoo_of("mlp")
  before = (folder / zoo.MANIFEST).read_bytes()
  chosen = catalogue.setting("lstm", ROBOT, None, "tiny", 1)
  use(monkeypatch, tmp_path / "trained", datasets=babbled)
  actions("lstm")
  with pytest.raises(ValueError, match="over its budget"):
    zoo.add(
      [(path, kind) for _, path, kind in catalogue.cache_files(chosen)],
      {},
      folder,
      budget_bytes=zoo.size_bytes(zoo.read_manifest(folder)),
    )
  assert (folder / zoo.MANIFEST).read_bytes() == before
  assert not list(folder.glob(f"{checkpoints.CHECKPOINT_FOLDER}/lstm-*"))


def test_removing_an_agent_keeps_the_forward_models_that_another_agent_in_the_zoo_reads(
  run_wide_homes, tmp_path, monkeypatch, capsys
):
  # One zoo of every learned agent's seed-0 weights (trained once per run in the run's home of
  # ROBOT), emptied one agent at a time through the command line.
  folder = tmp_path / "zoo"
  use(monkeypatch, run_wide_homes(ROBOT))
  files_of = {}
  for agent_name in LEARNED_AGENTS:
    agents.make(agent_name, ROBOT, 0, "tiny")
    files_of[agent_name] = catalogue.cache_files(
      catalogue.setting(agent_name, ROBOT, None, "tiny", 1)
    )
    zoo.add([(path, kind) for _, path, kind in files_of[agent_name]], {}, folder)
  relative = lambda path: path.relative_to(run_wide_homes(ROBOT)).as_posix()
  argv = ["--robot", ROBOT, "--profile", "tiny", "--seeds", "1", "--zoo", str(folder)]
  for done, agent_name in enumerate(LEARNED_AGENTS):
    capsys.readouterr()
    assert cli.main(["zoo", "remove", "--agent", agent_name, *argv]) == 0
    removed = {line.split()[1] for line in capsys.readouterr().out.splitlines()[:-1]}
    left = zoo.read_manifest(folder)
    kept = {relative(path) for name in LEARNED_AGENTS[done + 1 :] for _, path, _ in files_of[name]}
    own = {relative(path) for _, path, _ in files_of[agent_name]}
    assert kept <= set(left) and own - kept <= removed and not removed & set(left)
    assert zoo.check_files(folder) == []  # Every listed file is there, and nothing else.
    assert cli.main(["zoo", "remove", "--agent", agent_name, *argv]) == cli.EXIT_USAGE
    error = capsys.readouterr().err
    assert "holds nothing of" in error and error.count("\n") == 1
  assert zoo.read_manifest(folder) == {}
  assert [path.name for path in folder.rglob("*")] == [zoo.MANIFEST]


def test_zoo_add_and_remove_take_the_seeds_named_with_seed_alone(
  run_wide_homes, tmp_path, monkeypatch
):
  # Seeds 0 and 1 trained in the run's home of ROBOT; `--seed K` adds or removes seed K's files
  # (checkpoint and forward models) and leaves the other seed's where they were.
  home = run_wide_homes(ROBOT)
  use(monkeypatch, home)
  for seed in (0, 1):
    agents.make("lstm", ROBOT, seed, "tiny")

  def files_of(seed):
    chosen = catalogue.setting("lstm", ROBOT, None, "tiny", None, [seed])
    assert chosen.seeds == (seed,)
    return {path.relative_to(home).as_posix() for _, path, _ in catalogue.cache_files(chosen)}

  (tmp_path / "results").mkdir()
  argv = ["--agent", "lstm", "--robot", ROBOT, "--profile", "tiny", "--zoo", str(tmp_path / "zoo")]
  add = ["zoo", "add", *argv, "--results", str(tmp_path / "results")]
  assert files_of(0) and not files_of(0) & files_of(1)
  assert cli.main([*add, "--seed", "1"]) == 0
  assert set(zoo.read_manifest(tmp_path / "zoo")) == files_of(1)
  assert cli.main([*add, "--seed", "1", "--seed", "0", "--seed", "1"]) == 0
  assert set(zoo.read_manifest(tmp_path / "zoo")) == files_of(0) | files_of(1)
  assert cli.main(["zoo", "remove", *argv, "--seed", "0"]) == 0
  assert set(zoo.read_manifest(tmp_path / "zoo")) == files_of(1)
  assert zoo.check_files(tmp_path / "zoo") == []


def run_command(results, seeds=2):
  return [
    "run",
    "--task",
    "spiral",
    "--agent",
    "lstm",
    "--robot",
    ROBOT,
    "--profile",
    "tiny",
    "--seeds",
    str(seeds),
    "--workers",
    "1",
    "--results",
    str(results),
  ]


def test_cli_run_add_and_verify_reproduce_a_record_from_the_zoo(
  babbled, tmp_path, monkeypatch, capsys
):
  use(monkeypatch, tmp_path / "trained", datasets=babbled)
  assert cli.main(run_command(tmp_path / "results")) == 0
  ((path, trained),) = records.read_folder(tmp_path / "results")
  folder = tmp_path / "zoo"
  assert (
    cli.main(
      [
        "zoo",
        "add",
        "--agent",
        "lstm",
        "--robot",
        ROBOT,
        "--profile",
        "tiny",
        "--results",
        str(tmp_path / "results"),
        "--zoo",
        str(folder),
      ]
    )
    == 0
  )
  entries = zoo.read_manifest(folder).values()
  assert {entry.kind for entry in entries} == {"agent", "forward"}
  assert all(entry.records == (path.name,) for entry in entries if entry.kind == "agent")
  assert {entry.physics for entry in entries} == {versions.current().name}  # As the record's.
  # A fresh clone: an empty data home re-scores the record without babbling or training.
  use(monkeypatch, tmp_path / "empty", folder)
  with monkeypatch.context() as patched:
    no_training(patched)
    assert cli.main(run_command(tmp_path / "rescored")) == 0
  ((_, rescored),) = records.read_folder(tmp_path / "rescored")
  assert rescored["per_seed"] == trained["per_seed"]
  assert len(rescored["zoo"]["files"]) == 2 and "zoo" not in trained
  assert not (tmp_path / "empty" / "datasets").exists()
  capsys.readouterr()
  assert (
    cli.main(["zoo", "verify", "--results", str(tmp_path / "results"), "--zoo", str(folder)]) == 0
  )
  out = capsys.readouterr().out
  assert out.count("identical (") == 2 and "2 of 2 re-scored seeds agree" in out
  board = leaderboard.build(tmp_path / "results")
  assert board.verified == {path.name}  # In the ledger beside the results: verified.
  assert (
    cli.main(
      ["zoo", "verify", "--quick", "--results", str(tmp_path / "results"), "--zoo", str(folder)]
    )
    == 0
  )
  assert "1 of 1 re-scored seeds agree" in capsys.readouterr().out
  assert verified.read(tmp_path / "results")[path.name]["seeds"] == [0, 1]  # Quick: kept.


def test_verify_reports_a_record_the_zoo_does_not_reproduce(babbled, tmp_path, monkeypatch, capsys):
  use(monkeypatch, tmp_path / "trained", datasets=babbled)
  assert cli.main(run_command(tmp_path / "results", seeds=1)) == 0
  assert (
    cli.main(
      [
        "zoo",
        "add",
        "--agent",
        "lstm",
        "--robot",
        ROBOT,
        "--profile",
        "tiny",
        "--seeds",
        "1",
        "--results",
        str(tmp_path / "results"),
        "--zoo",
        str(tmp_path / "zoo"),
      ]
    )
    == 0
  )
  ((path, record),) = records.read_folder(tmp_path / "results")
  record["per_seed"][0]["mean_reward"] /= 2  # A record that these weights did not score.
  _reseal(record, path)
  capsys.readouterr()
  assert (
    cli.main(
      ["zoo", "verify", "--results", str(tmp_path / "results"), "--zoo", str(tmp_path / "zoo")]
    )
    == cli.EXIT_FAILURE
  )
  captured = capsys.readouterr()
  assert "DIFFERS: differs in mean_reward" in captured.out
  assert verified.read(tmp_path / "results") == {}  # Not verified.
  assert _without_reference_lines(captured.err) == [
    "softbench: error: 1 re-scored seeds differ from their records"
  ]
  # A damaged zoo file is named before anything is re-scored.
  (checkpoint,) = (tmp_path / "zoo" / checkpoints.CHECKPOINT_FOLDER).glob("*.pt")
  checkpoint.write_bytes(checkpoint.read_bytes()[:-1])
  assert (
    cli.main(
      ["zoo", "verify", "--results", str(tmp_path / "results"), "--zoo", str(tmp_path / "zoo")]
    )
    == cli.EXIT_USAGE
  )
  assert "sha256 differs" in capsys.readouterr().err


def _reseal(record: dict, path) -> None:
  records.write(
    {key: value for key, value in record.items() if key != records.INTEGRITY_FIELD}, path
  )


def test_zoo_add_links_only_the_records_its_weights_made(babbled, tmp_path, monkeypatch, capsys):
  use(monkeypatch, tmp_path / "trained", datasets=babbled)
  assert cli.main(run_command(tmp_path / "results", seeds=1)) == 0
  ((made, record),) = records.read_folder(tmp_path / "results")
  chosen = catalogue.setting("lstm", ROBOT, None, "tiny", 1)
  named = record["weights"]["per_seed"][0]["files"]
  home = tmp_path / "trained"
  assert named == {
    path.relative_to(home).as_posix(): zoo.file_sha256(path)
    for _, path, _ in catalogue.cache_files(chosen)
  }
  other = json.loads(json.dumps(record))  # Scored with other weights (a retrained checkpoint).
  checkpoint = next(path for path in named if path.startswith(checkpoints.CHECKPOINT_FOLDER))
  other["weights"]["per_seed"][0]["files"][checkpoint] = "0" * 64
  _reseal(other, tmp_path / "results" / made.name.replace(".json", "-other.json"))
  older = {key: value for key, value in record.items() if key != "weights"}  # Names none.
  _reseal(older, tmp_path / "results" / made.name.replace(".json", "-older.json"))
  argv = [
    *("zoo", "add", "--agent", "lstm", "--robot", ROBOT, "--profile", "tiny", "--seeds", "1"),
    *("--results", str(tmp_path / "results")),
  ]
  capsys.readouterr()
  assert cli.main([*argv, "--zoo", str(tmp_path / "zoo")]) == 0
  (entry,) = [e for e in zoo.read_manifest(tmp_path / "zoo").values() if e.kind == "agent"]
  assert entry.records == (made.name,)
  out = capsys.readouterr().out
  assert f"not linked {made.name.replace('.json', '-older.json')}: it names no weights" in out
  assert "-other.json" not in out
  assert cli.main([*argv, "--link-unchecked", "--zoo", str(tmp_path / "zoo-all")]) == 0
  (entry,) = [e for e in zoo.read_manifest(tmp_path / "zoo-all").values() if e.kind == "agent"]
  assert entry.records == tuple(sorted([made.name, made.name.replace(".json", "-older.json")]))


def test_a_record_naming_weights_of_a_seed_it_lacks_is_refused(babbled, tmp_path, monkeypatch):
  use(monkeypatch, tmp_path / "trained", datasets=babbled)
  assert cli.main(run_command(tmp_path / "results", seeds=1)) == 0
  ((path, record),) = records.read_folder(tmp_path / "results")
  record["weights"]["per_seed"].append({**record["weights"]["per_seed"][0], "seed": 1})
  with pytest.raises(records.RecordError, match="weights names seeds"):
    _reseal(record, path)


@pytest.mark.parametrize("command", ["add", "remove"])
@pytest.mark.parametrize(
  "argv,message",
  [
    (["--agent", "zero", "--robot", ROBOT], "agents trained on babbling"),
    (["--agent", "lstm", "--robot", "tendon-0"], "1 to 10 modules, got 0"),
    (["--agent", "lstm"], "name the setting"),
    (["--protocol", "exp1s", "--robot", ROBOT], "drop --robot"),
    (["--protocol", "exp2s"], "unknown protocol"),
    (["--family", "tendon-local"], "--family goes with --protocol"),
    (["--agent", "lstm", "--robot", ROBOT, "--seeds", "0"], "seeds must be a positive integer"),
    (["--agent", "lstm", "--robot", ROBOT, "--seed", "-1"], "seed must be an integer from 0"),
    (["--agent", "lstm", "--robot", ROBOT, "--seeds", "2", "--seed", "1"], "exclude each other"),
    (["--agent", "lstm", "--robot", ROBOT], "nothing of"),  # Trained (add), in the zoo (remove).
  ],
)
def test_zoo_add_and_remove_refuse_bad_input_in_one_line(
  command, argv, message, tmp_path, monkeypatch, capsys
):
  use(monkeypatch, tmp_path / "home")
  (tmp_path / "zoo").mkdir()
  assert (
    cli.main(["zoo", command, *argv, "--profile", "tiny", "--zoo", str(tmp_path / "zoo")])
    == cli.EXIT_USAGE
  )
  error = capsys.readouterr().err
  assert message in error and error.count("\n") == 1 and error.startswith("softbench: error:")
  assert not (tmp_path / "zoo" / zoo.MANIFEST).exists()


def test_zoo_commands_without_a_zoo_are_one_line_errors(tmp_path, monkeypatch, capsys):
  use(monkeypatch, tmp_path / "home")
  for argv in (["zoo", "list"], ["zoo", "verify"], ["zoo", "list", "--zoo", str(tmp_path)]):
    expected = 0 if "--zoo" in argv else cli.EXIT_USAGE
    assert cli.main(argv) == expected
  assert "turned off" in capsys.readouterr().err
  monkeypatch.setenv(zoo.VARIABLE, str(tmp_path / "missing"))
  assert cli.main(["zoo", "list"]) == cli.EXIT_USAGE
  assert "no zoo at" in capsys.readouterr().err
  assert cli.main(["zoo", "verify", "--agents", "nobody", "--zoo", str(tmp_path)]) == cli.EXIT_USAGE
  assert "unknown agent" in capsys.readouterr().err


def test_exp1s_networks_come_from_the_zoo(two_stages, tmp_path, monkeypatch, capsys):
  argv = [
    "run",
    "--protocol",
    "exp1s",
    "--agent",
    "smpl",
    "--profile",
    "tiny",
    "--seeds",
    "1",
    "--workers",
    "1",
  ]
  assert cli.main([*argv, "--results", str(tmp_path / "results")]) == 0
  ((path, trained),) = [
    (path, record) for path, record in records.read_folder(tmp_path / "results")
  ]
  assert (
    cli.main(
      [
        "zoo",
        "add",
        "--protocol",
        "exp1s",
        "--profile",
        "tiny",
        "--seeds",
        "1",
        "--results",
        str(tmp_path / "results"),
        "--zoo",
        str(tmp_path / "zoo"),
      ]
    )
    == 0
  )
  (entry,) = zoo.read_manifest(tmp_path / "zoo").values()
  assert entry.kind == "agent" and entry.records == (path.name,)
  use(monkeypatch, tmp_path / "empty", tmp_path / "zoo")
  with monkeypatch.context() as patched:
    no_training(patched)
    assert cli.main([*argv, "--results", str(tmp_path / "rescored")]) == 0
  ((_, rescored),) = records.read_folder(tmp_path / "rescored")
  assert rescored["per_seed"] == trained["per_seed"] and rescored["zoo"]["files"]
  # `zoo verify` re-scores the Exp1S record too (its kept episodes inside the empty data home).
  verify = ["zoo", "verify", "--results", str(tmp_path / "results"), "--zoo", str(tmp_path / "zoo")]
  with monkeypatch.context() as patched:
    no_training(patched)
    assert cli.main(verify) == 0
  assert f"{path.name} seed 0: identical" in capsys.readouterr().out


def test_the_repositorys_zoo_is_intact_within_its_budget_and_links_committed_records():
  committed = CHECKOUT / "zoo"
  entries = zoo.read_manifest(committed)
  assert entries, "the repository's zoo lists no file"
  assert zoo.check_files(committed) == []  # Every file listed, with its sha256; none unlisted.
  assert all((committed / path).stat().st_size == entry.bytes for path, entry in entries.items())
  assert zoo.size_bytes(entries) <= zoo.BUDGET_BYTES
  # Finished weights only: an unfinished training's state grows the history at every save.
  assert {entry.kind for entry in entries.values()} <= set(zoo.KINDS) == {"agent", "forward"}
  assert not [path for path in committed.rglob("*") if ".partial" in path.name]
  linked = {record for entry in entries.values() for record in entry.records}
  missing = sorted(linked - {path.name for path in (CHECKOUT / "leaderboard/results").iterdir()})
  assert not missing, f"the zoo links records that leaderboard/results lacks: {missing}"
