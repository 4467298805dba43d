"""Hyperparameter tuning (``softbench tune``) and the committed hyperparameters of every learned
agent, on tiny studies."""

import inspect
import json
import shutil

import pytest

from softbench import agents
from softbench import cli
from softbench import profiles
from softbench import robots
from softbench import tuning
from softbench.agents import hyperparameters
from softbench.learning import checkpoints
from softbench.learning import inverse as inverse_training

LEARNED = agents.babbling_learners()  # The agents tuning takes.


@pytest.fixture(autouse=True)
def shared_home(tmp_path_factory, babbled_home):
  """One data home for the file, holding tendon-2's tiny dataset: forward models are made once."""
  babbled_home(tmp_path_factory.getbasetemp() / "tuning_home")


def tune(tmp_path, *options, agent="mlp", trials=2):
  return cli.main(
    [
      "tune",
      "--agent",
      agent,
      "--robot",
      "tendon-2",
      "--profile",
      "tiny",
      "--trials",
      str(trials),
      "--storage",
      f"sqlite:///{tmp_path / 'studies.db'}",
      *options,
    ]
  )


def test_study_runs_resumes_and_writes_its_summary(tmp_path, capsys):
  summary_file = tmp_path / "summary.json"
  assert tune(tmp_path, "--summary", str(summary_file)) == 0
  out = capsys.readouterr().out
  first = json.loads(summary_file.read_text())
  assert [row["number"] for row in first["trial_table"]] == [0, 1]
  assert first["trials"]["complete"] + first["trials"]["pruned"] == 2
  previous = hyperparameters.values("mlp", "tendon-2")
  assert first["previous_values"]["params"] == previous  # Trial 0: the values in use.
  assert first["trial_table"][0]["params"] == previous
  assert first["best"]["value"] == min(
    row["value"] for row in first["trial_table"] if row["state"] == "complete"
  )
  assert f"best trial {first['best']['trial']}: validation MSE" in out
  assert str(summary_file) in out

  assert tune(tmp_path, "--summary", str(summary_file), trials=3) == 0  # Resumes from SQLite.
  resumed = json.loads(summary_file.read_text())
  assert [row["number"] for row in resumed["trial_table"]] == [0, 1, 2]
  assert resumed["trial_table"][:2] == first["trial_table"]
  assert tune(tmp_path, "--summary", str(summary_file), trials=3) == 0  # Nothing left to do.
  assert len(json.loads(summary_file.read_text())["trial_table"]) == 3

  # Trial n's sampler is seeded with n: the resumed study is the one run in one go.
  at_once = tmp_path / "at_once.json"
  assert tune(tmp_path, "--study", "at-once", "--summary", str(at_once), trials=3) == 0
  assert [row["params"] for row in json.loads(at_once.read_text())["trial_table"]] == [
    row["params"] for row in resumed["trial_table"]
  ]


def test_confirm_trains_the_choice_at_the_full_epoch_budget(tmp_path, capsys):
  summary_file = tmp_path / "confirmed.json"
  assert (
    tune(
      tmp_path,
      "--study",
      "short",
      "--epochs",
      "1",
      "--confirm",
      "--summary",
      str(summary_file),
      trials=1,
    )
    == 0
  )
  summary = json.loads(summary_file.read_text())
  assert summary["trial_epochs"] == 1 and summary["max_epochs"] == 2
  check = summary["full_budget"]
  assert check["epochs"] == 2 and check["best"] == check["previous"]  # One trial: the same values.
  # The same seed and data: the first epoch is the trial's, and the best of two is no worse.
  assert check["previous"] <= summary["previous_values"]["value"]
  assert "at the profile's 2 epochs: previous values" in capsys.readouterr().out


def test_adopt_commits_the_best_values_with_the_summary(tmp_path, monkeypatch, capsys):
  table = tmp_path / "hyperparameters.json"
  shutil.copy(hyperparameters.PATH, table)
  monkeypatch.setattr(hyperparameters, "PATH", table)
  assert tune(tmp_path, "--adopt", "--summary", str(tmp_path / "smpl.json"), agent="smpl") == 0
  summary = json.loads((tmp_path / "smpl.json").read_text())
  entry = hyperparameters.entry("smpl", "tendon-2")
  assert entry["params"] == summary["best"]["params"]
  assert entry["study"]["best"] == summary["best"] and "trial_table" not in entry["study"]
  assert hyperparameters.values("smpl", "tendon-3") == hyperparameters.values(
    "smpl", "tendon-3", path=hyperparameters.PATH
  )  # Other robots keep theirs.


@pytest.mark.parametrize("agent", LEARNED)
def test_committed_values_fit_every_learned_agent(agent):
  table = hyperparameters.load()
  for robot, entry in table["agents"][agent].items():
    robots.make(robot)
    assert hyperparameters.check_params(agent, entry["params"]) == entry["params"]
  arm = robots.make("tendon-2")  # No entry of its own: the default robot's values.
  params = hyperparameters.values(agent, arm.name)
  assert params == table["agents"][agent][table["default_robot"]]["params"]
  learner = tuning.study.learner(agent)
  views = learner.views(arm)
  model = inverse_training._inverse_model(views, learner.per_module, learner.make_model, params)
  assert model.action_size == (views[-1].action_size if learner.per_module else arm.action_dim)
  # Every tuned setting reaches the model or the optimiser.
  _, config = inverse_training.training_configs(0, profiles.get("tiny"), params)
  for name, value in inverse_training.training_settings(params).items():
    assert getattr(config, name) == value
  factory = inspect.signature(learner.make_model).parameters if not learner.per_module else {}
  assert set(inverse_training.model_settings(params)) <= set(factory)


@pytest.mark.parametrize("agent", LEARNED)
def test_a_changed_value_changes_the_checkpoint_key(agent, tmp_path, monkeypatch):
  arm, profile = robots.make("tendon-3"), profiles.get("tiny")
  views = tuning.study.learner(agent).views(arm)
  key = lambda: (
    checkpoints.trained_config(
      agent, arm, views, 0, profile, hyperparameters.values(agent, arm.name)
    ).key
  )
  before = key()
  table = json.loads(hyperparameters.PATH.read_text())
  params = table["agents"][agent]["tendon-3"]["params"]
  params["learning_rate"] = 2e-3 if params["learning_rate"] != 2e-3 else 3e-3
  changed = tmp_path / "hyperparameters.json"
  changed.write_text(json.dumps(table))
  monkeypatch.setattr(hyperparameters, "PATH", changed)
  assert key() != before


def test_learned_agents_train_with_the_committed_values(tmp_path, monkeypatch, babbled_home):
  babbled_home(tmp_path / "home")
  agents.make("mlp", "tendon-2", 0, "tiny")
  table = json.loads(hyperparameters.PATH.read_text())
  table["agents"]["mlp"]["tendon-3"]["params"]["hidden_size"] = 32
  changed = tmp_path / "hyperparameters.json"
  changed.write_text(json.dumps(table))
  monkeypatch.setattr(hyperparameters, "PATH", changed)
  agent = agents.make("mlp", "tendon-2", 0, "tiny")  # A new checkpoint, not the stale one.
  assert agent.inverse.network[0].out_features == 32
  assert len(list((tmp_path / "home" / checkpoints.CHECKPOINT_FOLDER).glob("mlp-*.pt"))) == 2


@pytest.mark.parametrize(
  "change,message",
  [
    (
      lambda t: t["agents"]["mlp"]["tendon-3"]["params"].update(learning_rate=1.0),
      "learning_rate = 1.0 is outside its range",
    ),
    (
      lambda t: t["agents"]["lstm"]["tendon-3"]["params"].update(batch_size=32.0),
      "batch_size = 32.0 is outside its range",
    ),
    (
      lambda t: t["agents"]["smpl"]["tendon-3"]["params"].update(hidden_size=64),
      "hyperparameters must be",
    ),
    (
      lambda t: t["agents"].update(oracle={"tendon-3": {"params": {}, "study": None}}),
      "agent 'oracle' has no hyperparameters to tune",
    ),
    (lambda t: t["agents"]["vae-lstm"]["tendon-3"].pop("study"), "expected the keys params"),
  ],
)
def test_a_bad_hyperparameters_file_is_refused_with_one_line(change, message, tmp_path):
  table = json.loads(hyperparameters.PATH.read_text())
  change(table)
  path = tmp_path / "hyperparameters.json"
  path.write_text(json.dumps(table))
  with pytest.raises(ValueError, match=message) as error:
    hyperparameters.load(path)
  assert "\n" not in str(error.value)


@pytest.mark.parametrize(
  "argv,message",
  [
    (["--agent", "oracle", "--robot", "tendon-2"], "unknown agent"),
    (["--agent", "zero", "--robot", "tendon-2"], "not trained on babbling"),
    (["--agent", "mlp", "--robot", "tendon-0"], "1 to 10 modules"),
    (["--agent", "mlp", "--robot", "tendon-2", "--trials", "0"], "trials must be"),
    (["--agent", "mlp", "--robot", "tendon-2", "--profile", "huge"], "unknown profile"),
    (
      ["--agent", "mlp", "--robot", "tendon-2", "--profile", "tiny", "--epochs", "3"],
      "epochs must be a whole number from 1 to the tiny profile's 2",
    ),
    (
      ["--agent", "mlp", "--robot", "tendon-2", "--storage", "not-a-url"],
      "cannot open the study storage",
    ),
    (
      ["--agent", "mlp", "--robot", "tendon-2", "--storage", "sqlite:////no/such/dir/x.db"],
      "cannot open the study storage",
    ),
  ],
)
def test_tune_refuses_bad_input_with_one_line(argv, message, capsys):
  assert cli.main(["tune", *argv]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and message in lines[0]


def test_a_study_resumed_with_other_settings_is_refused(tmp_path, capsys):
  assert tune(tmp_path, "--study", "shared", trials=1) == 0
  capsys.readouterr()  # The first study's output (with the collection's bar, run alone).
  assert tune(tmp_path, "--study", "shared", agent="lstm", trials=1) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and "was made with other settings (agent" in lines[0]


def test_agents_verbose_shows_the_hyperparameters(capsys):
  assert cli.main(["agents", "--verbose"]) == 0
  out = capsys.readouterr().out
  for agent in LEARNED:
    first_name = next(iter(hyperparameters.values(agent, "tendon-3")))
    assert f"tendon-3: {first_name} " in out.split(f"\n{agent} ")[1]
