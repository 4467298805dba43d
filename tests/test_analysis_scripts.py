"""The scripts behind the docs' figures (docs/analysis) keep running against the current API, on
tiny data; the early-stopping script's best-validation agent is the one `softbench run` trains."""

import importlib.util
import json
import pathlib
import re
import signal
import sys
import threading

import example_strategy
import pytest

from softbench import cli
from softbench import data
from softbench import records
from softbench import robots
from softbench.agents import hyperparameters
from softbench.agents import learners
from softbench.continual import streams
from softbench.data import splits
from softbench.learning import inverse as inverse_training
from softbench.robots import versions
from softbench.runners import run
from softbench.runners import run_settings

ANALYSIS = pathlib.Path(__file__).parent.parent / "docs" / "analysis"


@pytest.fixture(autouse=True)
def data_home(tmp_path, babbled_home):
  """A data home of each test's own, holding the tiny datasets of the robots the scripts use."""
  for robot in ("tendon-1", "tendon-2", "tendon-local-2"):
    babbled_home(tmp_path, robot)


def load_script(name: str):
  """docs/analysis/NAME.py as a module."""
  spec = importlib.util.spec_from_file_location(name, ANALYSIS / f"{name}.py")
  module = importlib.util.module_from_spec(spec)
  spec.loader.exec_module(module)
  return module


def run_script(name: str, arguments: list[str], monkeypatch, capsys) -> str:
  """Runs docs/analysis/NAME.py's main() with these arguments; returns what it printed."""
  module = load_script(name)
  monkeypatch.setattr(sys, "argv", [name, *arguments])
  module.main()
  return capsys.readouterr().out


def _smpl_circle_record() -> dict:
  """`softbench run`'s record of SMPL on tendon-2's circle, tiny profile, seed 0: what the SMPL
  analysis scripts must reproduce with SMPL's own settings."""
  return run.execute(
    run_settings.settings("circle", "smpl", "tendon-2", seeds=1, profile="tiny"),
    show_progress=False,
    workers=1,
  )


def test_action_identifiability_reports_every_module_in_both_views(monkeypatch, capsys):
  data.collect("tendon-2", samples=200, seed=0, progress=False)
  out = run_script("action_identifiability", ["tendon-2", "--samples", "200"], monkeypatch, capsys)
  for split in data.SPLITS:
    assert re.search(rf"^  {split} +tip mean", out, re.MULTILINE)
  assert re.findall(r"^  module (\d): residual variance", out, re.MULTILINE) == ["1", "2"]
  assert re.findall(r"to module (\d)'s actions \(SMPL's column", out) == ["1", "2"]
  fractions = re.search(r"fraction of variance left +\[([^\]]+)\]", out).group(1).split()
  assert len(fractions) == 4 and all(float(value) >= 0.0 for value in fractions)


def test_early_stopping_keeps_the_agent_softbench_run_trains(monkeypatch, capsys):
  out = run_script(
    "early_stopping",
    [
      "--agent",
      "lstm",
      "--robot",
      "tendon-1",
      "--task",
      "circle",
      "--profile",
      "tiny",
      "--epochs",
      "2",
      "--keep",
      "1",
      "2",
    ],
    monkeypatch,
    capsys,
  )
  scores = dict(
    re.findall(
      r"seed 0, (best validation|after epoch \d)[^:]*: position error "
      r"([0-9.]+) mm",
      out,
    )
  )
  assert set(scores) == {"best validation", "after epoch 1", "after epoch 2"}
  record = run.execute(
    run_settings.settings("circle", "lstm", "tendon-1", seeds=1, profile="tiny"),
    show_progress=False,
    workers=1,
  )
  assert scores["best validation"] == f"{record['per_seed'][0]['position_mm']['mean']:.2f}"


def test_validation_loss_reports_every_seed_of_every_agent(monkeypatch, capsys):
  out = run_script(
    "validation_loss",
    ["--agents", "mlp", "--robot", "tendon-1", "--profile", "tiny", "--seeds", "2"],
    monkeypatch,
    capsys,
  )
  losses = re.findall(
    r"^mlp seed (\d): validation loss ([0-9.]+), test loss ([0-9.]+)$", out, re.MULTILINE
  )
  assert [seed for seed, _, _ in losses] == ["0", "1"]
  assert all(0 < float(validation) < 10 and 0 < float(test) < 10 for _, validation, test in losses)
  assert losses[0][1:] != losses[1][1:]  # Each seed its own model.


def test_exp1s_column_retrains_the_column_exp1s_trained(two_stages, monkeypatch, capsys, tmp_path):
  results = tmp_path / "results"
  assert (
    cli.main(
      [
        "run",
        "--protocol",
        "exp1s",
        "--agent",
        "smpl",
        "--profile",
        "tiny",
        "--seeds",
        "1",
        "--results",
        str(results),
      ]
    )
    == 0
  )
  (path,) = results.glob("smpl-exp1s-tiny-*.json")
  spiral = json.loads(path.read_text())["per_seed"][0]["scores"]["closed"]["spiral"][1]
  capsys.readouterr()
  # The tiny profile trains 2 epochs without stopping early: the run's own settings.
  out = run_script(
    "exp1s_column",
    [
      "--configuration",
      "2",
      "--seed",
      "0",
      "--profile",
      "tiny",
      "--epochs",
      "2",
      "--settings",
      "tuned:0",
      "tuned:1",
      "--tasks",
      "spiral",
    ],
    monkeypatch,
    capsys,
  )
  scores = re.findall(
    r"pose-loss weight (\d+): tendon-2 spiral, closed loop in physics: end "
    r"effector ([0-9.]+) mm, ([0-9.]+) deg",
    out,
  )
  assert [weight for weight, _, _ in scores] == ["0", "1"]
  assert scores[0][1:] == (f"{spiral['position_mm']:.2f}", f"{spiral['orientation_deg']:.2f}")
  assert len(re.findall(r"best validation [0-9.]+ at epoch [12]; test action MSE", out)) == 2


def test_forward_coupling_compares_both_forward_models_of_every_module(monkeypatch, capsys):
  data.collect("tendon-local-2", samples=200, seed=0, progress=False)
  out = run_script("forward_coupling", ["tendon-local-2", "--profile", "tiny"], monkeypatch, capsys)
  found = re.findall(
    r"^tendon-local-2 module (\d): .* actuation ([0-9.]+), from every module's "
    r"([0-9.]+) \(ratio ([0-9.]+)\)$",
    out,
    re.MULTILINE,
  )
  assert [module for module, *_ in found] == ["1", "2"]
  for _, own, every, ratio in found:
    assert float(own) > 0 and float(every) > 0
    assert float(ratio) == pytest.approx(float(own) / float(every), rel=0.02)


def test_plant_comparison_sets_both_robots_side_by_side(monkeypatch, capsys):
  # On the committed records: the default-profile spiral of tendon-3 and tendon-local-3.
  results = pathlib.Path(__file__).parent.parent / "leaderboard" / "results"
  argv = ["--results", str(results), "--physics", "v0"]  # v0's records are complete.
  out = run_script("plant_comparison", argv, monkeypatch, capsys)
  header = next(line for line in out.splitlines() if line.startswith("| agent |"))
  spiral = header.split(" | ").index("spiral")
  row = next(line for line in out.splitlines() if line.startswith("| smpl |"))
  first, second = row.split(" | ")[spiral].split(" -> ")
  assert re.fullmatch(r"[0-9.]+ ± [0-9.]+", first) and re.fullmatch(r"[0-9.]+ ± [0-9.]+", second)
  ranked = re.search(r"^spiral on tendon-local-3, learned agents from best: (.+)$", out, re.M)
  assert "smpl" in ranked.group(1)


def test_reach_completion_reports_every_mode_of_every_agent(monkeypatch, capsys, tmp_path):
  out_file = tmp_path / "table.json"
  out = run_script(
    "reach_completion",
    ["--robot", "tendon-1", "--agents", "mlp", "--profile", "tiny", "--targets", "2"]
    + ["--out", str(out_file)],
    monkeypatch,
    capsys,
  )
  table = json.loads(out_file.read_text())
  assert list(table) == [f"mlp {helpers}" for helpers in ("complete", "nearest", "hold", "share")]
  for row in table.values():
    low, median, high = row["episode_mean_mm"]
    assert 0 <= low <= median <= high and len(row["final_mm"]) == 3
  assert out.count("(quartiles over 2 targets)") == 4


def test_smpl_width_reproduces_smpl_at_the_papers_size_and_trains_other_sizes(monkeypatch, capsys):
  out = run_script(
    "smpl_width",
    [
      *("--robot", "tendon-2", "--profile", "tiny", "--task", "circle"),
      *("--columns", "32x2", "16x1"),
    ],
    monkeypatch,
    capsys,
  )
  scores = dict(re.findall(r"^smpl (\d+x\d) .* position error ([0-9.]+) mm", out, re.MULTILINE))
  assert set(scores) == {"32x2", "16x1"}
  record = _smpl_circle_record()
  assert scores["32x2"] == f"{record['per_seed'][0]['position_mm']['mean']:.4f}"
  assert scores["16x1"] != scores["32x2"]


def test_smpl_forward_views_reproduces_smpl_and_trains_through_every_actuation(monkeypatch, capsys):
  out = run_script(
    "smpl_forward_views",
    ["--robot", "tendon-2", "--profile", "tiny", "--task", "circle", "--views", "own", "every"],
    monkeypatch,
    capsys,
  )
  scores = dict(
    re.findall(r"^smpl forward views (\w+) .* position error ([0-9.]+) mm", out, re.MULTILINE)
  )
  assert set(scores) == {"own", "every"}
  record = _smpl_circle_record()
  assert scores["own"] == f"{record['per_seed'][0]['position_mm']['mean']:.4f}"
  assert scores["every"] != scores["own"]


def test_smpl_joint_columns_trains_every_column_at_once_and_reads_the_record(
  monkeypatch, capsys, tmp_path
):
  results = tmp_path / "results"
  record = _smpl_circle_record()
  records.write(record, results / "smpl.json")
  arguments = ["--robot", "tendon-2", "--profile", "tiny", "--task", "circle"]
  out = run_script(
    "smpl_joint_columns", [*arguments, "--results", str(results)], monkeypatch, capsys
  )
  (line,) = re.findall(
    r"^smpl joint columns, recorded preceding actuation, tendon-2 tiny seed 0: .*$",
    out,
    re.MULTILINE,
  )
  joint = re.search(r"circle position error ([0-9.]+) mm", line).group(1)
  recorded = f"{record['per_seed'][0]['position_mm']['mean']:.4f}"
  assert f"the record: {recorded} mm" in line
  arm = robots.make("tendon-2")
  network, _ = inverse_training.untrained(
    learners.views(arm, per_module=True), True, None, hyperparameters.values("smpl", arm.name)
  )
  assert f"({sum(p.numel() for p in network.parameters()):,} parameters trained" in line
  acted = run_script(
    "smpl_joint_columns",
    [*arguments, "--results", str(results), "--preceding", "acted"],
    monkeypatch,
    capsys,
  )
  (acted_line,) = re.findall(r"^smpl joint columns, acted preceding .*$", acted, re.MULTILINE)
  assert re.search(r"position error ([0-9.]+) mm", acted_line).group(1) != joint
  assert joint != recorded  # Trained otherwise, so scored otherwise.


def test_sweep_vs_loop_times_a_part_both_ways_to_the_same_records_and_resumes(
  monkeypatch, capsys, tmp_path
):
  work = tmp_path / "grid"
  grid = ["--robot", "tendon-1", "--tasks", "circle", "--profile", "tiny", "--seeds", "2"]
  grid += ["--work", str(work)]
  part = [*grid, "--part", "baselines", "--way"]
  with pytest.raises(SystemExit, match="collect the dataset first"):
    run_script("sweep_vs_loop", [*part, "loop"], monkeypatch, capsys)
  run_script("sweep_vs_loop", [*grid, "--way", "dataset"], monkeypatch, capsys)
  for way in ("loop", "sweep", "loop"):  # The second loop finds its records: nothing to run.
    run_script("sweep_vs_loop", [*part, way], monkeypatch, capsys)
  out = run_script("sweep_vs_loop", ["--work", str(work), "--report"], monkeypatch, capsys)
  lines = out.splitlines()
  assert re.fullmatch(r"dataset: [0-9.]+ s", lines[0])
  assert lines[1:4] == [
    "learners (smpl mlp lstm vae-lstm): loop not finished, sweep not finished",
    "bilstm (bilstm): loop not finished, sweep not finished",
    "sac (sac): loop not finished, sweep not finished",
  ]
  number = "[0-9.]+"
  assert re.fullmatch(
    rf"baselines \(zero random\): loop {number} s in 2 stretches \(0 interrupted\), "
    rf"sweep {number} s in 1 stretches \(0 interrupted\)",
    lines[4],
  )
  assert re.fullmatch(rf"  the sweep took {number} of the loop", lines[5])
  assert re.fullmatch(rf"loop: {number} s, sweep: {number} s \(.*\)", lines[6])
  assert lines[7:] == ["records of both ways: 2, with the same scores seed for seed: 2"]
  collected = sorted(path.name for path in (work / "dataset" / "home" / "datasets").iterdir())
  for way in ("loop", "sweep"):  # Each in a data home of its own, holding the collected dataset.
    home = work / "baselines" / way / "home"
    assert sorted(path.name for path in (home / "datasets").iterdir()) == collected
    finished = json.loads((work / "baselines" / way / "finished.json").read_text())
    assert sorted(finished["scores"]) == ["random-tendon-1-circle", "zero-tendon-1-circle"]


def test_sweep_vs_loop_counts_an_interrupted_stretch_and_passes_the_interruption_on(tmp_path):
  timing = load_script("sweep_vs_loop")
  saved = tmp_path / "saved"  # The command's "resumable state", written when Ctrl-C reaches it.
  command = [
    sys.executable,
    "-c",
    "import pathlib, time\n"
    "try:\n  time.sleep(60)\n"
    f"except KeyboardInterrupt:\n  pathlib.Path({str(saved)!r}).touch(); raise SystemExit(130)",
  ]
  main = threading.get_ident()
  # Ctrl-C's handler, also where the tests were started in the background (SIGINT ignored).
  previous = signal.signal(signal.SIGINT, signal.default_int_handler)
  try:
    threading.Timer(2.0, signal.pthread_kill, (main, signal.SIGINT)).start()
    with pytest.raises(KeyboardInterrupt):
      timing._timed(command, tmp_path, "sleeper")
  finally:
    signal.signal(signal.SIGINT, previous)
  (stretch,) = [json.loads(line) for line in (tmp_path / "times.jsonl").read_text().splitlines()]
  assert stretch["interrupted"] and stretch["returncode"] == 130 and saved.exists()
  assert 1.5 < stretch["seconds"] < 30


def test_stack_speed_measures_each_stack_in_a_fresh_process(monkeypatch, capsys):
  # Both "stacks" are this interpreter here; CI's machines have one stack each.
  out = run_script(
    "stack_speed",
    ["--robots", "tendon-1", "--rounds", "1", "--v0", sys.executable, "--v1", sys.executable],
    monkeypatch,
    capsys,
  )
  (row,) = re.findall(
    r"^\| tendon-1 \| ([\d,]+) \(([\d.]+)\) \| ([\d,]+) \(([\d.]+)\) \| ([\d.]+) \|$", out, re.M
  )
  assert all(float(value.replace(",", "")) > 0 for value in row)
  assert f"MuJoCo {versions.engine_version()}" in out


def test_ewc_lambda_scores_both_configurations_for_every_lambda(monkeypatch, capsys):
  printed = run_script(
    "ewc_lambda", ["--profile", "tiny", "--lambdas", "0", "1e7"], monkeypatch, capsys
  )
  rows = [json.loads(line) for line in printed.splitlines() if line.startswith("{")]
  assert [row["lambda"] for row in rows] == [0.0, 1e7]
  for row in rows:
    assert row["mean"] == pytest.approx((row["first"] + row["second"]) / 2)


def test_stream_coverage_measures_every_configuration_of_a_stream(registries, monkeypatch, capsys):
  streams.register(example_strategy.LOADED)  # tendon-1, then carrying 5 g.
  arguments = ["--streams", "loaded-pair", "--profile", "tiny", "--radius-mm", "1000"]
  out = run_script("stream_coverage", arguments, monkeypatch, capsys)
  number = r" +([\d.]+)"
  rows = re.findall(rf"^loaded-pair +(\d+ g){number * 5}$", out, re.MULTILINE)
  assert [row[0] for row in rows] == ["0 g", "5 g"]
  dataset = data.collect("tendon-1", samples=200, seed=0, progress=False)
  training = sum(piece.samples for piece in splits.split_pieces(dataset.episode_lengths)["train"])
  for _, samples, spread, nearest, farthest, within in rows:
    assert int(samples) == training
    assert 0 < float(nearest) <= float(farthest) and float(spread) > 0
    assert float(within) == training  # Every sample lies within 1 m of a 5 cm arm's targets.


def test_stream_actions_compares_a_strategys_modules_with_the_reference(
  registries, monkeypatch, capsys
):
  streams.register(example_strategy.LOADED)  # tendon-1, then carrying 5 g.
  arguments = ["--stream", "loaded-pair", "--strategy", "independent", "--profile", "tiny"]
  out = run_script("stream_actions", [*arguments, "--seeds", "0", "1"], monkeypatch, capsys)
  number = r" +([\d.]+)"
  module = rf"m1{number}{number}{number}"  # tendon-1: one module.
  rows = re.findall(rf"^(\d+ g) +(reference|independent) +(\d+){number} +{module}$", out, re.M)
  expected = [
    (load, agent, seed)
    for seed in ("0", "1")
    for load in ("0 g", "5 g")
    for agent in ("reference", "independent")
  ]
  assert [row[:3] for row in rows] == expected
  for _, agent, _, error, mean, largest, saturated in rows:
    assert float(error) >= 0 and 0 <= float(mean) <= float(largest) <= 1
    assert 0 <= float(saturated) <= 1
  reference_errors = [float(row[3]) for row in rows if row[1] == "reference"]
  learned_errors = [float(row[3]) for row in rows if row[1] == "independent"]
  assert max(reference_errors) < min(learned_errors)  # It plans on the simulator itself.


def test_rescore_on_v1_goes_on_where_its_out_file_stopped(monkeypatch, capsys, tmp_path):
  from softbench import zoo
  from softbench.robots import base
  from softbench.runners import zoo_verification

  monkeypatch.setattr(base.SoftArm, "physics_sha256", base.SoftArm.physics_sha256)  # Restored.
  monkeypatch.setattr(zoo, "restore", zoo.restore)
  rescored = []

  def moved_by_half_a_millimetre(record: dict, seed: int) -> dict:  # No physics in this test.
    rescored.append(record["task"] + "-" + record["eval_mode"])
    (entry,) = [entry for entry in record["per_seed"] if entry["seed"] == seed]
    return {**entry, "position_mm": {"mean": entry["position_mm"]["mean"] + 0.5}}

  monkeypatch.setattr(zoo_verification, "rescored", moved_by_half_a_millimetre)
  out = tmp_path / "rows.md"
  arguments = ["--agents", "smpl", "--profile", "default", "--seeds", "1", "--out", str(out)]
  printed = run_script("rescore_on_v1", arguments, monkeypatch, capsys)
  rows = [line for line in out.read_text().splitlines() if line.startswith("| smpl-")]
  assert len(rows) == len(rescored) >= 2 and printed.splitlines()[2:] == rows
  assert all(" | 1 | " in line and line.endswith(" | 5.00e-01 |") for line in rows)

  kept = rows[:-2]  # As if stopped before its last two records.
  out.write_text("".join(line + "\n" for line in out.read_text().splitlines()[:2] + kept))
  rescored.clear()
  run_script("rescore_on_v1", arguments, monkeypatch, capsys)
  assert len(rescored) == 2
  assert [line for line in out.read_text().splitlines() if line.startswith("| smpl-")] == rows


def test_rescore_on_v1_keys_robots_by_their_v0_hash_and_never_trains(tmp_path):
  from softbench import zoo

  rescore = load_script("rescore_on_v1")
  entries = [
    zoo.ZooFile("a.pt", "0", 1, "agent", "a", {"robot": "tendon-3", "robot_xml_sha256": "old"}),
    zoo.ZooFile(
      "b.pt", "0", 1, "agent", "b", {"robot": "tendon-3", "robot_xml_sha256": "new"}, (), "v1"
    ),
  ]
  assert rescore.v0_hashes(entries) == {"tendon-3": "old"}
  assert rescore.v0_hashes(entries[::-1]) == {"tendon-3": "old"}

  present = tmp_path / "present.pt"
  present.write_bytes(b"weights")
  restore = rescore.refusing_to_train(lambda cache_file: [])
  assert restore(present) == []
  with pytest.raises(SystemExit, match="the zoo has no missing.pt; re-scoring would train it"):
    restore(tmp_path / "missing.pt")
