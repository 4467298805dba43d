"""Continual strategies on streams (``softbench run --protocol continual``), over every registered
strategy and stream: each learns a tiny two-stage stream (tendon-1, then tendon-2) and is scored
in physics after every stage; SMPL forgets nothing to the bit; finetuning forgets and replay and
EWC forget less; an outside strategy and stream join by ``register``; bad input is one line."""

import contextlib
import dataclasses
import json
import time

import example_strategy
import numpy as np
import pytest
import torch

from smpl import snapshots
from softbench import cli
from softbench import leaderboard
from softbench import profiles
from softbench import records
from softbench.continual import learning as continual_learning
from softbench.continual import metrics as continual_metrics
from softbench.continual import strategies
from softbench.continual import streams
from softbench.continual.strategies import base as strategy_base
from softbench.data import views
from softbench.leaderboard import continual_board
from softbench.leaderboard import ranking
from softbench.leaderboard import text as leaderboard_text
from softbench.records import continual as continual_records
from softbench.records.fields import METRICS
from softbench.runners import continual as exp1s_runner
from softbench.runners import continual_stream

PAIR = streams.Stream(
  "pair", "tendon-1, then tendon-2", lambda family: streams._arms(family, (1, 2))
)
TINY = profiles.get("tiny")
# Long enough for a shared network to learn each stage, so that learning the second one can
# undo the first (2 epochs hardly move it); 10 epochs of the tiny dataset take about 4 s.
LEARNING = dataclasses.replace(TINY, max_epochs=10, patience=10)


@pytest.fixture
def pair(registries, tmp_path, babbled_home):
  """``PAIR`` registered, in a data home with tendon-1's and tendon-2's tiny datasets."""
  for robot in ("tendon-1", "tendon-2"):
    babbled_home(tmp_path / "home", robot)
  streams.register(PAIR)
  return PAIR


def seed_entry(strategy: str, profile: profiles.Profile = TINY) -> dict:
  return continual_stream.run_seed(
    0, continual_stream.ContinualSettings(strategy, "pair", "tendon", profile, 1)
  )


@pytest.mark.parametrize("name", streams.STREAMS)
@pytest.mark.parametrize("family", ["tendon", "tendon-local"])
def test_every_stream_is_a_sequence_of_configurations_one_view_reads(name, family):
  stream = streams.get(name)
  configurations = stream.configurations(family)
  assert len(configurations) >= 2
  assert len({configuration.label for configuration in configurations}) == len(configurations)
  pose_sizes = {views.View.end_effector(c.robot).pose_size for c in configurations}
  assert len(pose_sizes) == 1
  assert len({c.robot.physics_sha256() for c in configurations}) == len(configurations)
  for configuration in configurations:
    assert configuration.robot.name.startswith(f"{family}-")
    assert json.loads(json.dumps(configuration.describe())) == configuration.describe()


def test_payload_and_degrade_change_the_physics_as_described():
  loaded = streams.get("payload").configurations()
  empty = loaded[0].robot.mass()
  for configuration, grams in zip(loaded, streams.PAYLOADS_G):
    assert configuration.robot.mass() - empty == pytest.approx(grams / streams.GRAMS_PER_KG)
  degraded = streams.get("degrade").configurations()
  for configuration, gain in zip(degraded, streams.DEGRADE_GAINS):
    faults = configuration.robot.faults
    assert all(fault.gain == gain and fault.module == streams.DEGRADED_MODULE for fault in faults)
    assert len(faults) == (0 if gain == 1.0 else streams.CABLES_PER_MODULE)


@pytest.mark.parametrize("name", strategies.STRATEGIES)
def test_every_strategy_learns_a_two_stage_stream_scored_in_physics(name, pair):
  run = continual_stream.ContinualSettings(name, "pair", "tendon", TINY, 1)
  record = records.seal(continual_stream.execute(run, show_progress=False, workers=1))
  records.validate(record, name)  # Schema, hash and the continual checks.
  (seed,) = record["per_seed"]
  first, second = seed["stages"]
  assert [len(stage["scores"]) for stage in seed["stages"]] == [1, 2]
  assert all(
    np.isfinite(score[m]) for s in seed["stages"] for score in s["scores"] for m in METRICS
  )
  continual = strategies.strategy_class(name).continual
  for stage in seed["stages"]:
    assert stage["parameters"] > 0 and stage["carried_values"] >= stage["parameters"]
    if continual:
      assert max(stage["trained_on"], default=0) <= stage["stage"]
  if not continual:  # Every stage's data at the first stage.
    assert first["trained_on"] == [0, 1]
  matrix = continual_metrics.error_matrix(seed)
  assert np.isnan(matrix[0, 1]) and np.all(np.isfinite(matrix[np.tril_indices(2)]))
  table = continual_stream.table(record)
  assert "average final error" in table and "forgetting" in table


def test_smpl_forgets_nothing_to_the_bit(pair):
  first, second = seed_entry("smpl", LEARNING)["stages"]
  assert second["scores"][0] == first["scores"][0]
  assert second["model_pose_mse"][0] == first["model_pose_mse"][0]
  assert second["model_action_mse"][0] == first["model_action_mse"][0]
  assert second["parameters_trained"] < second["parameters"]  # The new column only.


def test_finetune_forgets_and_replay_and_ewc_forget_less(pair):
  rises = {}
  for name in ("finetune", "replay", "ewc"):
    first, second = seed_entry(name, LEARNING)["stages"]
    rises[name] = {
      "physics_mm": second["scores"][0]["position_mm"] - first["scores"][0]["position_mm"],
      "action_mse": second["model_action_mse"][0] - first["model_action_mse"][0],
    }
  for measure, rise in rises["finetune"].items():
    assert rise > 0, (measure, rises)
    assert rises["replay"][measure] < rise and rises["ewc"][measure] < rise, (measure, rises)


def test_an_outside_strategy_and_stream_run_from_the_command_line(
  registries, tmp_path, babbled_home, capsys
):
  babbled_home(tmp_path / "home", "tendon-1")
  strategies.register("first-only", example_strategy.ENTRY)
  streams.register(example_strategy.LOADED)
  results = tmp_path / "results"
  argv = ["run", "--protocol", "continual", "--stream", "loaded-pair", "--agent", "first-only"]
  argv += ["--profile", "tiny", "--seeds", "1", "--results", str(results)]
  assert cli.main(argv) == 0
  assert "first-only on stream loaded-pair" in capsys.readouterr().out
  (path,) = results.glob("first-only-continual-loaded-pair-tiny-*.json")
  record = records.read(path)
  assert [c["payload_kg"] for c in record["configurations"]] == list(example_strategy.PAYLOADS_KG)
  first, second = record["per_seed"][0]["stages"]
  assert second["trained_on"] == [] and second["parameters_trained"] == 0
  assert path.with_name(f"{path.stem}-matrix.png").stat().st_size > 0


@pytest.mark.parametrize(
  "flags, message",
  [
    (["--agent", "smpl"], "needs --stream STREAM"),
    (["--stream", "sideways", "--agent", "smpl"], "unknown stream 'sideways'"),
    (["--stream", "grow", "--agent", "lstm"], "unknown continual strategy 'lstm'"),
    (["--stream", "grow", "--agent", "first-only"], "it needs one action size"),
    (["--stream", "grow", "--agent", "ewc", "--family", "rope"], "unknown tendon family 'rope'"),
    (["--stream", "grow", "--agent", "ewc", "--task", "spiral"], "drop --task"),
    (["--stream", "grow", "--agent", "ewc", "--eval", "model"], "drop --eval"),
    (["--stream", "grow", "--agent", "ewc", "--seeds", "0"], "seeds"),
  ],
)
def test_bad_continual_input_is_one_line_and_exit_2(registries, flags, message, capsys):
  strategies.register("first-only", example_strategy.ENTRY)
  assert cli.main(["run", "--protocol", "continual", *flags]) == 2
  err = capsys.readouterr().err.strip().splitlines()
  assert len(err) == 1 and message in err[0], err


def test_softbench_streams_lists_every_stream_and_strategy(registries, capsys):
  streams.register(PAIR)
  assert cli.main(["streams", "--json", "--family", "tendon-local"]) == 0
  listed = json.loads(capsys.readouterr().out)
  assert [entry["name"] for entry in listed["streams"]] == list(streams.STREAMS)
  assert [entry["name"] for entry in listed["strategies"]] == list(strategies.STRATEGIES)
  pair = next(entry for entry in listed["streams"] if entry["name"] == "pair")
  assert [c["robot"] for c in pair["configurations"]] == ["tendon-local-1", "tendon-local-2"]
  assert cli.main(["streams"]) == 0
  printed = capsys.readouterr().out
  assert all(name in printed for name in (*streams.STREAMS, *strategies.STRATEGIES))
  assert cli.main(["streams", "--family", "rope"]) == 2
  assert "unknown tendon family 'rope'" in capsys.readouterr().err


def test_stream_without_its_protocol_is_one_line(capsys):
  assert cli.main(["run", "--task", "spiral", "--agent", "zero", "--stream", "grow"]) == 2
  assert "--stream goes with --protocol continual" in capsys.readouterr().err


def test_registries_refuse_taken_and_malformed_names(registries):
  with pytest.raises(ValueError, match="registered already"):
    streams.register(streams.get("grow"))
  with pytest.raises(ValueError, match="lowercase"):
    strategies.register("Two Words", example_strategy.ENTRY)
  with pytest.raises(ValueError, match="unknown task"):
    streams.register(dataclasses.replace(PAIR, task="juggling"))


def test_the_continual_figures_follow_their_definitions():
  nan = np.nan
  errors = np.array([[2.0, nan, nan], [5.0, 4.0, nan], [3.0, 6.0, 1.0]])
  assert continual_metrics.average_final(errors) == pytest.approx(10 / 3)
  assert continual_metrics.forgetting_per_configuration(errors).tolist() == [3.0, 2.0]
  reference = np.array([[2.0, nan, nan], [2.0, 8.0, nan], [2.0, 8.0, 2.0]])
  assert continual_metrics.transfer_per_stage(errors, reference).tolist() == [0.5, 0.5]
  assert continual_metrics.curve_area([4.0, 2.0, 3.0], 5) == pytest.approx((4 + 2 * 4) / 5)
  assert continual_records.PROTOCOL == "continual"


def test_smpl_on_a_growing_stream_is_exp1s(pair, two_stages):
  # Exp1S (shortened to tendon-1, tendon-2 by two_stages) trains the same network, to the bit.
  exp1s = exp1s_runner.build(0, TINY)
  *_, (strategy, _, _) = continual_learning.learn("smpl", PAIR, "tendon", 0, TINY)
  assert strategy_base.tensors_digest(strategy.module.network.state_dict()) == (
    strategy_base.tensors_digest(exp1s.network.state_dict())
  )


def test_the_leaderboard_shows_a_table_per_stream_with_forward_transfer(
  pair, tmp_path, assert_regenerates_identically
):
  results = tmp_path / "results"
  for name in ("finetune", strategies.REFERENCE):
    run = continual_stream.ContinualSettings(name, "pair", "tendon", TINY, 2)
    record = continual_stream.execute(run, show_progress=False, workers=1)
    records.write_new(record, continual_stream.record_path(record, results))
  board = leaderboard.build(results)
  (group,) = board.continual
  assert group.title == "Continual · pair (tendon), profile tiny"
  assert {entry.label for entry in group.entries} == {"finetune", strategies.REFERENCE}
  rows = {row[0]: row for row in continual_board.table(group).rows}
  assert rows[strategies.REFERENCE][5] == "-" and rows["finetune"][5] != "-"
  finetune = next(entry for entry in group.entries if entry.label == "finetune")
  expected = continual_metrics.transfer(finetune.record, group.reference.record)
  assert rows["finetune"][5].startswith(
    ranking.mean_and_std(ranking.Estimate.of([v * 100 for v in expected["forward_transfer"]]))
  )
  printed = leaderboard_text.report(board, results)
  assert group.title in printed and "forward transfer (%)" in printed
  markdown, html, _ = leaderboard.write(board, results, tmp_path / "site")
  for page in (markdown, html):
    text = page.read_text()
    assert group.title in text and "normalised tip error (%) of each configuration" in text
  assert_regenerates_identically(results, tmp_path)


def test_a_stage_stopped_mid_training_counts_its_earlier_epochs_when_it_resumes(pair, monkeypatch):
  """A stage stopped after two epochs, whose clock ran epoch_s an epoch, then resumed: its
  training_seconds holds those two epochs, not only the time since the resume."""
  epoch_s, stopped_after = 500.0, 2
  monkeypatch.setattr(snapshots, "SAVE_INTERVAL_S", 0.0)  # A snapshot after every epoch.

  def stop_after_two(report):
    if report.epoch + 1 == stopped_after:
      raise KeyboardInterrupt

  clock = iter(range(0, 10**6, int(epoch_s)))
  with monkeypatch.context() as stopped:
    stopped.setattr(time, "perf_counter", lambda: float(next(clock)))
    stopped.setattr(  # Only the stage's training, not the forward models' before it.
      continual_learning.progress_bars,
      "epochs",
      lambda label, *_: contextlib.nullcontext(
        stop_after_two if "pair seed" in (label or "") else None
      ),
    )
    with pytest.raises(KeyboardInterrupt):
      next(continual_learning.learn("independent", PAIR, "tendon", 0, LEARNING))
  started = time.perf_counter()
  _, _, summary = next(continual_learning.learn("independent", PAIR, "tendon", 0, LEARNING))
  since_resume = time.perf_counter() - started
  assert summary["epochs"][0] > stopped_after  # It went on training after the resume.
  assert (
    stopped_after * epoch_s <= summary["training_seconds"] <= stopped_after * epoch_s + since_resume
  )


@pytest.mark.parametrize("name", strategies.STRATEGIES)
def test_a_run_that_resumes_after_a_cached_stage_learns_the_next_to_the_same_weights(name, pair):
  *_, (whole, _, _) = continual_learning.learn(name, PAIR, "tendon", 0, TINY)
  configurations = PAIR.configurations("tendon")
  cache = continual_learning.folder(
    continual_learning.config(name, PAIR.name, configurations, 0, TINY)
  )
  continual_learning.stage_path(cache, 1).unlink()  # Stopped after its first stage.
  *_, (resumed, _, _) = continual_learning.learn(name, PAIR, "tendon", 0, TINY)
  first, second = whole.module.state_dict(), resumed.module.state_dict()
  assert first.keys() == second.keys()
  for key in first:
    assert torch.equal(first[key], second[key]), key
