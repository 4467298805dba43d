"""Result records (schema, integrity hash) and the leaderboard (ranking, markdown and HTML pages).

One real record comes from ``softbench run``'s ``execute`` (the zero agent, tiny profile); the
others are variants of it (another agent, date or scale of the errors), sealed again.
"""

import copy
import csv
import json
import math
import os
import pathlib
import warnings

import jsonschema
import numpy as np
import pytest
from scipy import stats

from softbench import agents
from softbench import cli
from softbench import leaderboard
from softbench import metrics
from softbench import records
from softbench.leaderboard import aggregate
from softbench.leaderboard import csv_table
from softbench.leaderboard import filters
from softbench.leaderboard import log_chart
from softbench.leaderboard import overview
from softbench.leaderboard import ranking
from softbench.leaderboard import verified
from softbench.leaderboard import winners
from softbench.records import exp1s as exp1s_records
from softbench.runners import run
from softbench.runners import run_settings


@pytest.fixture(scope="module")
def real_record(tmp_path_factory) -> dict:
  """A 2-seed record of the zero agent on tendon-1 circle, as ``softbench run`` makes it."""
  with pytest.MonkeyPatch.context() as patch:
    patch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.mktemp("leaderboard_home")))
    settings = run_settings.settings("circle", "zero", "tendon-1", seeds=2, profile="tiny")
    return run.execute(settings, show_progress=False, workers=1)


def variant(
  record: dict, agent: str | None = None, date: str | None = None, scale: float = 1.0, **fields
) -> dict:
  """A sealed copy of ``record`` with another agent or date, ``fields`` replaced (``None``
  removes one), then errors times ``scale``."""
  changed = copy.deepcopy(record)
  changed["agent"] = agent or changed["agent"]
  changed["date"] = date or changed["date"]
  for name, value in copy.deepcopy(fields).items():
    if value is None:
      changed.pop(name, None)
    else:
      changed[name] = value
  for seed in changed["per_seed"]:
    for name in records.METRICS:
      if name in seed:
        seed[name]["per_module"] = [value * scale for value in seed[name]["per_module"]]
        seed[name]["mean"] = float(np.mean(seed[name]["per_module"]))
  return records.seal(changed)


def position_only(record: dict) -> dict:
  """``record`` as if the task had been ``reach`` (no orientation error), unsealed."""
  changed = copy.deepcopy(record)
  changed["task"] = "reach"
  for seed in changed["per_seed"]:
    del seed["orientation_deg"]
  return changed


def write_raw(record: dict, path: pathlib.Path, reseal: bool = True) -> pathlib.Path:
  """Writes ``record`` without checking it; ``reseal`` recomputes the hash of its content first,
  so that a check other than the hash refuses it."""
  record = dict(record)
  if reseal:
    record[records.INTEGRITY_FIELD] = records.content_sha256(record)
  path.write_text(json.dumps(record, indent=2))
  return path


def test_schema_round_trip(real_record, tmp_path):
  path = tmp_path / "record.json"
  sealed = records.write(real_record, path)
  assert sealed[records.INTEGRITY_FIELD] == records.content_sha256(real_record)
  assert path.read_text() == records.dumps(sealed)
  assert records.read(path) == sealed
  assert records.seal(sealed) == sealed  # Sealing again changes nothing.
  assert sealed["version"] == records.VERSION == run.RECORD_VERSION
  schema = records.schema()
  jsonschema.Draft202012Validator.check_schema(schema)  # Usable by any JSON Schema tool...
  jsonschema.validate(sealed, schema)  # ...which accepts what softbench writes.
  reach = records.seal(position_only(real_record))
  assert records.read(write_raw(reach, tmp_path / "reach.json", reseal=False)) == reach


def _tamper(record):
  record["per_seed"][0]["position_mm"]["per_module"][0] += 0.01


def _set(path, value):
  def change(record):
    *parents, last = path
    target = record
    for key in parents:
      target = target[key]
    if value is None:
      del target[last]
    else:
      target[last] = value

  return change


MALFORMED = {
  "hand-edited number": (_tamper, False, "does not match its sha256"),
  "no hash": (_set(["sha256"], None), False, "'sha256' is a required property"),
  "missing field": (_set(["robot"], None), True, "'robot' is a required property"),
  "negative error": (
    _set(["per_seed", 0, "position_mm", "mean"], -1.0),
    True,
    r"per_seed\[0\].position_mm.mean: -1.0 is less than the minimum of 0",
  ),
  "NaN": (_set(["per_seed", 1, "mean_reward"], math.nan), False, "not a finite number"),
  "unknown task": (_set(["task"], "juggle"), True, "'juggle' is not one of"),
  "extra scalar field": (_set(["score"], 3), True, "score: unknown field"),
  "old version": (_set(["version"], 1), True, "record version 1 is not read"),
  "other format": (_set(["format"], "csv"), True, "not a result record"),
  "format not a string": (_set(["format"], []), True, r"not a result record \(format \[\]"),
  "astronomical error": (
    _set(["per_seed", 0, "position_mm", "per_module"], [1e308]),
    True,
    r"per_module\[0\]: 1e\+308 is greater than the maximum of 1000000",
  ),
  "integer beyond floats": (
    _set(["per_seed", 0, "position_mm", "per_module"], [10**400]),
    True,
    "is greater than the maximum of 1000000",
  ),
  "astronomical wall time": (
    _set(["wall_time_s"], 1e300),
    True,
    r"wall_time_s: 1e\+300 is greater than the maximum",
  ),
  "seed count": (_set(["seeds"], 3), True, "seeds is 3 but per_seed has 2 entries"),
  "repeated seed": (_set(["per_seed", 1, "seed"], 0), True, "repeats a seed"),
  "module count": (
    _set(["per_seed", 0, "position_mm", "per_module"], [1.0, 1.0]),
    True,
    "has 2 values for 1 scored modules",
  ),
  "mean over modules": (
    _set(["per_seed", 0, "normalised_tip_percent", "mean"], 123.0),
    True,
    "is not the mean of its per_module values",
  ),
  "module beyond the robot": (_set(["scored_modules"], [2]), True, "beyond tendon-1's 1"),
  "robot": (_set(["robot"], "tendon-0"), True, "robot: "),
  "trajectory": (_set(["trajectory"], "path.csv"), True, "trajectory goes with task custom"),
  "date": (_set(["date"], "yesterday"), True, "not an ISO 8601 date"),
}


@pytest.mark.parametrize("case", MALFORMED)
def test_a_malformed_or_edited_record_is_refused_with_one_line(case, real_record, tmp_path):
  change, reseal, message = MALFORMED[case]
  record = records.seal(real_record)
  change(record)
  path = write_raw(record, tmp_path / "bad.json", reseal)
  with pytest.raises(records.RecordError, match=message) as raised:
    records.read(path)
  assert str(raised.value).startswith(f"{path}: ") and "\n" not in str(raised.value)


def test_the_cli_refuses_a_folder_with_a_bad_record(real_record, tmp_path, capsys):
  records.write(real_record, tmp_path / "good.json")
  bad = records.seal(real_record)
  _tamper(bad)
  write_raw(bad, tmp_path / "edited.json", reseal=False)
  (tmp_path / "broken.json").write_text('{"format": ')
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and "broken.json: not valid JSON" in lines[0]  # Files in name order.
  (tmp_path / "broken.json").unlink()
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  assert "edited.json: content does not match its sha256" in capsys.readouterr().err


UNPARSABLE = {
  "nested too deeply": ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
  "too many digits": ('{"format": ' + "1" * 5000 + "}", "integer string conversion"),
}


@pytest.mark.parametrize("case", UNPARSABLE)
def test_an_unparsable_record_is_refused_with_one_line_naming_it(case, tmp_path, capsys):
  text, message = UNPARSABLE[case]
  path = tmp_path / "bad.json"
  path.write_text(text)
  with pytest.raises(records.RecordError, match=message) as raised:
    records.read(path)
  assert str(raised.value).startswith(f"{path}: ") and "\n" not in str(raised.value)
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  assert capsys.readouterr().err == f"softbench: error: {raised.value}\n"


def test_a_broken_link_is_refused_as_one(real_record, tmp_path, capsys):
  records.write(real_record, tmp_path / "good.json")
  (tmp_path / "gone.json").symlink_to(tmp_path / "nowhere.json")
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  (line,) = capsys.readouterr().err.splitlines()
  assert line.startswith(f"softbench: error: {tmp_path / 'gone.json'}: a broken link")
  with pytest.raises(FileNotFoundError):  # A plain missing file is no record error.
    records.read(tmp_path / "missing.json")


def test_an_unreadable_results_folder_is_an_error_not_an_empty_one(
  real_record, tmp_path, monkeypatch, capsys
):
  records.write(real_record, tmp_path / "good.json")
  scandir = os.scandir

  def forbidden(path=".", *args):
    if pathlib.Path(path) == tmp_path:
      raise PermissionError(13, "Permission denied", str(path))
    return scandir(path, *args)

  monkeypatch.setattr(os, "scandir", forbidden)
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  captured = capsys.readouterr()
  assert captured.err == (
    f"softbench: error: {tmp_path}: the folder of result records cannot "
    f"be read (Permission denied)\n"
  )
  assert "no result records" not in captured.out


def test_run_refuses_to_write_a_malformed_record(real_record, tmp_path):
  record = copy.deepcopy(real_record)
  record["per_seed"][0]["position_mm"]["mean"] = math.inf
  with pytest.raises(records.RecordError, match="not a finite number"):
    records.write(record, tmp_path / "record.json")
  assert not list(tmp_path.iterdir())


def test_bootstrap_interval():
  values = [3.0, 1.0, 4.0, 1.5, 5.0]
  estimate = ranking.Estimate.of(values)
  expected = stats.bootstrap(
    (np.array(values),),
    np.mean,
    n_resamples=10_000,
    method="percentile",
    rng=np.random.default_rng(0),
  )
  assert estimate.interval == (expected.confidence_interval.low, expected.confidence_interval.high)
  assert min(values) <= estimate.interval[0] < estimate.mean < estimate.interval[1] <= max(values)
  assert (estimate.mean, estimate.std) == (np.mean(values), np.std(values))
  assert ranking.Estimate.of([2.0]).interval is None
  with warnings.catch_warnings():
    warnings.simplefilter("error")
    assert ranking.Estimate.of([2.0, 2.0]).interval == (2.0, 2.0)


@pytest.fixture
def results(real_record, tmp_path) -> pathlib.Path:
  """A results folder: three agents, an older record of one, one seed only, a reach record, a
  record with a fault section, and videos (a path and a URL)."""
  folder = tmp_path / "results"
  made = {
    "zero-old.json": variant(real_record, date="2020-01-01T00:00:00+00:00", scale=0.1),
    "zero.json": variant(real_record, video="videos/zero.mp4"),
    "good.json": variant(
      real_record, agent="good", scale=0.5, video="https://example.org/good.mp4"
    ),
    "bad.json": variant(real_record, agent="bad", scale=2.0),
    "single.json": variant(
      real_record, agent="single", scale=0.8, seeds=1, per_seed=real_record["per_seed"][:1]
    ),
    "reach.json": records.seal(position_only(real_record)),
    "fault.json": variant(real_record, fault={"module": 1, "kind": "dead"}),
  }
  for name, record in made.items():
    records.write(record, folder / name)
  return folder


def test_ranking(results):
  board = leaderboard.build(results)
  assert board.record_count == 7
  titles = [group.title for group in board.groups]
  assert titles == ["tendon-1 · circle", "tendon-1 · circle (with fault)", "tendon-1 · reach"]
  circle = board.groups[0]
  assert [entry.record["agent"] for entry in circle.entries] == ["good", "single", "zero", "bad"]
  assert [entry.path.name for entry in circle.superseded] == ["zero-old.json"]
  assert circle.entries[1].estimates["position_mm"].interval is None  # One seed.
  assert circle.metrics == records.METRICS
  assert board.groups[2].metrics == ("position_mm", "normalised_tip_percent")


# What each option of softbench leaderboard selects by, and how many of ``results``' 7 it keeps.
FIELDS = {"robots": "robot", "tasks": "task", "agents": "agent", "profiles": "profile"}


@pytest.mark.parametrize(
  "asked,count",
  [
    ({"agents": ("zero",)}, 4),
    ({"tasks": ("reach",)}, 1),
    ({"robots": ("tendon-1",), "profiles": ("tiny",)}, 7),
    ({"robots": ("tendon-2",)}, 0),
  ],
)
def test_a_filtered_leaderboard_holds_exactly_the_records_asked_for(asked, count, results, capsys):
  chosen = filters.RecordFilter(**asked)
  board = leaderboard.build(results, chosen)
  shown = [entry for group in board.groups for entry in (*group.entries, *group.superseded)]
  assert board.record_count == len(shown) == count
  for entry in shown:
    assert all(entry.record[FIELDS[axis]] in names for axis, names in asked.items())
  argv = [part for axis, names in asked.items() for part in (f"--{axis}", *names)]
  assert cli.main(["leaderboard", "--results", str(results), *argv]) == 0
  first = capsys.readouterr().out.splitlines()[0]
  assert f"of {chosen.describe()} in {results}" in first and (count == 0) == first.startswith("no ")


def test_an_exp1s_record_is_shown_when_all_its_arms_are_asked_for_and_no_task():
  (path, record), *_ = [
    loaded
    for loaded in records.read_folder(leaderboard.DEFAULT_RESULTS)
    if loaded[1]["format"] == exp1s_records.FORMAT
  ]
  arms = tuple(record["robots"])
  assert filters.RecordFilter(robots=arms, agents=("smpl",)).keeps(record), path
  assert not filters.RecordFilter(robots=arms[1:]).keeps(record)
  assert not filters.RecordFilter(tasks=("spiral",)).keeps(record)
  assert not filters.RecordFilter(agents=("lstm",)).keeps(record)


@pytest.mark.parametrize(
  "argv,message",
  [
    (["--robots", "tendon-0"], "1 to 10 modules"),
    (["--tasks", "juggle"], "unknown task"),
    (["--agents", "oracle"], "unknown agent"),
    (["--profiles", "huge"], "unknown profile"),
    (["--robots", "tendon-1", "--write"], "--write writes the whole leaderboard"),
  ],
)
def test_the_cli_refuses_bad_filters_in_one_line(argv, message, results, tmp_path, capsys):
  argv = ["leaderboard", "--results", str(results), "--out", str(tmp_path / "site"), *argv]
  assert cli.main(argv) == cli.EXIT_USAGE
  error = capsys.readouterr().err
  assert message in error and error.count("\n") == 1 and not (tmp_path / "site").exists()


def test_an_agent_that_learns_by_acting_shows_its_steps_and_ranks_with_the_others(
  real_record, tmp_path
):
  folder = tmp_path / "results"
  spent = {
    "per_seed": [
      {"seed": 0, "environment_steps": 30000, "episodes": 601, "wall_time_s": 1500.0},
      {"seed": 1, "environment_steps": 30000, "episodes": 601, "wall_time_s": 2100.0},
    ]
  }
  records.write(variant(real_record, agent="sac", scale=0.5, training=spent), folder / "sac.json")
  records.write(variant(real_record, zoo={"files": ["checkpoints/x.pt"]}), folder / "zero.json")
  (circle,) = leaderboard.build(folder).groups  # Neither section makes a group of its own.
  assert [entry.shown_setting for entry in circle.entries] == [
    ("sac (30,000 steps, 30 min per seed)", "tiny", "physics"),
    ("zero", "tiny", "physics"),
  ]
  with pytest.raises(records.RecordError, match="environment_steps"):
    variant(real_record, agent="sac", training={"per_seed": [{"seed": 0, "environment_steps": 0}]})


def test_the_overview_shows_every_plain_task_of_every_agent(results):
  board = leaderboard.build(results)
  (view,) = overview.overviews(board)
  assert (view.robot, view.profile, view.eval_mode) == ("tendon-1", "tiny", "physics")
  assert view.table.header == ("agent", "circle", "reach")
  rows = {row[0]: row[1:] for row in view.table.rows}
  assert list(rows) == ["zero", "bad", "good", "single"]  # Registered agents first.
  shown = 0
  for group in board.groups:
    for entry in group.entries if not group.variant else ():  # Not the fault's group.
      cell = rows[entry.record["agent"]][view.table.header.index(group.task) - 1]
      assert cell == ranking.mean_and_std(entry.estimates["position_mm"])
      shown += 1
  assert shown == 5 and rows["good"][1] == "-"  # Good has no reach record.
  assert "no table for this robot" in view.table.caption
  unrecorded = [agent for agent in agents.AGENTS if agent != "zero"]
  assert view.table.caption.endswith(f"; no record yet of {', '.join(unrecorded)}")


def test_the_overview_shows_the_papers_value_beside_ours(real_record, tmp_path):
  experiments = overview.paper()["experiments"]
  assert set(experiments) == {"tendon-3", "pneumatic-433"}
  for experiment in experiments.values():
    for scores in experiment["scores"].values():
      for pairs in scores.values():
        assert len(pairs) == len(experiment["agents"])
        assert all(mean > 0 and std >= 0 for mean, std in pairs)
  assert overview.paper_mean("tendon-3", "spiral", "smpl") == 1.24  # Table sim_robo_exp2S.
  assert overview.paper_mean("tendon-3", "reach", "smpl") is None  # Not in the paper.
  assert overview.paper_mean("tendon-3", "spiral", "zero") is None
  folder = tmp_path / "results"
  for robot in experiments:
    records.write(variant(real_record, agent="smpl", robot=robot), folder / f"{robot}.json")
  views = overview.overviews(leaderboard.build(folder))
  assert [view.robot for view in views] == ["pneumatic-433", "tendon-3"]
  for view, name in zip(views, ("Exp2R", "Exp2S")):
    ((agent, cell),) = view.table.rows
    assert f"the paper's {name} mean" in view.table.caption
    assert cell.endswith(f" ({overview.paper_mean(view.robot, 'circle', 'smpl'):.2f})")


def test_every_page_marks_the_figures_of_completed_targets(real_record, tmp_path):
  """A reach record whose agent completed the point (``helpers``) carries the mark in the
  overviews of the markdown page and the HTML page; one that held the other modules does not."""
  folder = tmp_path / "results"
  reach = position_only(real_record)
  records.write(variant(reach, agent="smpl", helpers="complete"), folder / "smpl.json")
  records.write(variant(reach, agent="lstm", helpers="hold"), folder / "lstm.json")
  board = leaderboard.build(folder)
  (view,) = overview.overviews(board)
  assert view.marks == {("smpl", "reach"): ranking.COMPLETED_MARK, ("lstm", "reach"): ""}
  cells = {row[0]: row[1] for row in view.table.rows}
  assert cells["smpl"].endswith(ranking.COMPLETED_MARK)
  assert not cells["lstm"].endswith(ranking.COMPLETED_MARK)
  leaderboard.write(board, folder, tmp_path / "site")
  page = (tmp_path / "site" / "index.html").read_text()
  overview_html = page[page.index(f'id="{view.anchor}"') :]
  overview_html = overview_html[: overview_html.index("</table>")]
  assert overview_html.count(ranking.COMPLETED_MARK) == 2  # The caption's note and smpl's cell.


def test_pages_contain_every_record(results, tmp_path, capsys):
  out = tmp_path / "site"
  assert cli.main(["leaderboard", "--results", str(results), "--write", "--out", str(out)]) == 0
  printed = capsys.readouterr().out
  markdown = (out / "README.md").read_text()
  page = (out / "index.html").read_text()
  assert "superseded: zero-old.json" in printed
  for path in results.glob("*.json"):
    assert f"(<../results/{path.name}>)" in markdown
    assert f'href="../results/{path.name}"' in page
  for text in (printed, markdown, page):
    assert "tendon-1 · circle (with fault)" in text and "tendon-1 · reach" in text
    assert "tendon-1 overview · tiny profile · physics" in text
  assert "(<../results/videos/zero.mp4>)" in markdown
  assert 'href="../results/videos/zero.mp4"' in page
  assert 'href="https://example.org/good.mp4"' in page
  board = leaderboard.build(results)
  settings = [{entry.setting[1:] for entry in group.entries} for group in board.groups]
  boards = sum(len(found) for found in settings) + len(overview.overviews(board))
  assert page.count('<table class="sortable">') == boards  # Every task board and overview.
  # A log-axis chart per metric of each task board (one profile and eval mode each).
  assert page.count("<svg") == len(aggregate.views(board)) + sum(
    len(found) * len(group.metrics) for found, group in zip(settings, board.groups)
  )
  for found in settings:
    for profile, eval_mode in found:
      assert f'data-profile="{profile}" data-eval="{eval_mode}"' in page
      assert (
        f'name="profile" value="{profile}"' in page and f'name="eval" value="{eval_mode}"' in page
      )
  assert "<link" not in page and "src=" not in page  # Self-contained: nothing to fetch.
  good = ranking.Estimate.of(
    [seed["position_mm"]["mean"] for seed in records.read(results / "good.json")["per_seed"]]
  )
  low, high = (ranking.number(bound, ranking.decimals_of(good.mean)) for bound in good.interval)
  assert ranking.cell(good) in markdown
  assert (
    f'data-value="{good.mean!r}">{ranking.mean_and_std(good)} <span class="ci">[{low}, {high}]'
    in page
  )
  assert 'href="leaderboard.csv"' in page


def test_the_csv_holds_every_shown_row_in_full(results, tmp_path):
  board = leaderboard.build(results)
  leaderboard.write(board, results, tmp_path)
  with open(tmp_path / csv_table.FILE_NAME, newline="") as file:
    rows = list(csv.DictReader(file))
  shown = [(group, entry) for group in board.groups for entry in group.entries]
  assert len(rows) == len(shown) and tuple(rows[0]) == csv_table.HEADER
  for row, (group, entry) in zip(rows, shown):
    assert (row["robot"], row["task"], row["variant"]) == (group.robot, group.task, group.variant)
    assert (row["agent"], row["profile"], row["eval_mode"]) == entry.setting
    assert row["record"] == pathlib.Path(os.path.relpath(entry.path, tmp_path)).as_posix()
    for metric in records.METRICS:
      estimate = entry.estimates.get(metric)
      if estimate is None:
        assert row[f"{metric}_mean"] == ""
        continue
      assert float(row[f"{metric}_mean"]) == estimate.mean  # In full, not rounded.
      assert float(row[f"{metric}_std"]) == estimate.std
      if estimate.interval is not None:
        low, high = estimate.interval
        assert (float(row[f"{metric}_ci_low"]), float(row[f"{metric}_ci_high"])) == (low, high)


@pytest.mark.parametrize("means", [(0.001, 0.5, 120.0), (0.0, 3.0, 3.0), (0.0, 0.0), (7.0,)])
def test_log_chart_bars_grow_with_the_mean_on_decade_ticks(means):
  estimates = [ranking.Estimate(mean, 0.0, (mean * 0.9, mean * 1.1)) for mean in means]
  chart = log_chart.chart([(f"row {i}", f"row {i}", e) for i, e in enumerate(estimates)], "c")
  widths = [bar.width for bar in chart.bars]
  assert all(0 <= width <= chart.right - chart.left for width in widths)
  for (mean_a, width_a), (mean_b, width_b) in zip(zip(means, widths), zip(means[1:], widths[1:])):
    assert (width_a < width_b) == (mean_a < mean_b) or mean_b <= 0
  assert [bar.width for bar, mean in zip(chart.bars, means) if mean <= 0] == [0.0] * means.count(0)
  positions = [x for x, _ in chart.ticks]
  assert positions == sorted(positions) and len(positions) >= 2
  assert chart.left <= positions[0] and positions[-1] <= chart.right
  for x, label in chart.ticks:  # A tick sits where its decade's value would end a bar.
    assert math.log10(float(label)) == pytest.approx(round(math.log10(float(label))))
  for bar, mean in zip(chart.bars, means):
    if mean > 0:
      low, high = bar.whisker
      assert low <= chart.left + bar.width <= high


def test_regenerating_is_deterministic(results, tmp_path, assert_regenerates_identically):
  assert_regenerates_identically(results, tmp_path)


def test_write_on_an_empty_folder(tmp_path, capsys):
  results = tmp_path / "results"
  results.mkdir()
  out = tmp_path / "site"
  assert cli.main(["leaderboard", "--results", str(results), "--write", "--out", str(out)]) == 0
  printed = capsys.readouterr().out
  assert f"no result records in {results}" in printed and "an empty folder" in printed
  for page in ("README.md", "index.html"):
    assert "No result records yet" in (out / page).read_text()


@pytest.mark.parametrize("write", [[], ["--write"]], ids=["report", "write"])
def test_a_missing_results_folder_is_refused(write, tmp_path, capsys):
  # It printed an empty leaderboard (exit 0), and --write replaced the pages with empty ones.
  results, out = tmp_path / "results", tmp_path / "site"
  argv = ["leaderboard", "--results", str(results), *write, "--out", str(out)]
  assert cli.main(argv) == cli.EXIT_USAGE
  assert capsys.readouterr().err == f"softbench: error: no folder of result records at {results}\n"
  assert not out.exists()


# Physics versions: never ranked together.


def test_records_of_two_physics_versions_are_ranked_apart(real_record, tmp_path, capsys):
  results = tmp_path / "results"
  results.mkdir()
  newer = variant(real_record, physics="v1", date="2026-12-07T00:00:00+00:00")
  older = variant(real_record, agent="random", scale=0.5, physics=None)  # Before versions: v0.
  for name, record in (("newer", newer), ("older", older)):
    records.write(record, results / f"{name}.json")
  board = leaderboard.build(results)
  assert board.physics == "v1" and [e.record["agent"] for e in board.groups[0].entries] == ["zero"]
  (earlier,) = board.earlier
  assert earlier.physics == "v0" and [e.record["agent"] for e in earlier.groups[0].entries] == [
    "random"
  ]  # The better v0 record is not ranked above the v1 one.
  assert board.of_physics("v0") is earlier and board.of_physics("v1") is board
  site = tmp_path / "site"
  leaderboard.write(board, results, site)
  page = (site / "README.md").read_text()
  assert "Current physics: physics v1" in page and "# Earlier physics: physics v0" in page
  html = (site / "index.html").read_text()
  assert 'id="physics-v0"' in html and "Earlier physics: physics v0" in html
  rows = list(csv.DictReader((site / csv_table.FILE_NAME).open()))
  assert [(row["physics"], row["agent"]) for row in rows] == [("v1", "zero"), ("v0", "random")]
  assert cli.main(["leaderboard", "--results", str(results)]) == 0
  assert "earlier physics: physics v0" in capsys.readouterr().out


def test_a_record_of_an_unknown_physics_version_is_refused(real_record, tmp_path):
  path = write_raw(variant(real_record) | {"physics": "v9"}, tmp_path / "x.json")
  with pytest.raises(records.RecordError, match="physics"):
    records.read(path)


@pytest.fixture
def contest(real_record, tmp_path) -> pathlib.Path:
  """Records where an oracle and a sanity baseline beat the learned agents, and lstm wins."""
  folder = tmp_path / "contest"
  for agent, scale in (("smpl", 1.0), ("lstm", 0.5), ("zero", 0.2), ("reference", 0.01)):
    records.write(variant(real_record, agent=agent, scale=scale), folder / f"{agent}.json")
  return folder


def test_the_first_screen_names_the_best_learned_agent_and_shows_the_oracle_apart(
  contest, tmp_path, capsys
):
  board = leaderboard.build(contest)
  (group,) = board.groups
  assert [entry.setting[0] for entry in group.entries] == ["zero", "lstm", "smpl", "reference"]
  assert ranking.places(group.entries) == ["1", "2", "3", ranking.ORACLE_PLACE]
  ((best,),) = [row.best for row in winners.rows(overview.overviews(board))]
  assert (best.agent, [agent for agent, _ in best.oracles]) == ("lstm", ["reference"])
  out = tmp_path / "site"
  assert cli.main(["leaderboard", "--results", str(contest), "--write", "--out", str(out)]) == 0
  printed = capsys.readouterr().out
  assert [line.split()[:2] for line in printed.splitlines() if "tiny" in line][-4:] == [
    ["1", "zero"],
    ["2", "lstm"],
    ["3", "smpl"],
    ["oracle", "reference"],
  ]
  page = (out / "index.html").read_text()
  first_screen = page[: page.index('<details id="methods">')]  # Before the methods and tables.
  assert '<section id="winners"><h2>Who is best</h2>' in first_screen
  assert f'<strong>lstm</strong> <span class="figure">{best.figure}</span>' in first_screen
  assert f"oracle reference {ranking.mean_and_std(best.oracles[0][1])}" in first_screen
  overview_html = page[page.index('<div class="board" id="overview-') :]
  overview_html = overview_html[: overview_html.index("</table>")]
  assert overview_html.count("★") == 2  # The caption's key and lstm's cell.
  assert 'class="figure best"' in overview_html.split("<tr>")[3]  # smpl, zero, lstm, reference.
  assert (
    overview_html.rstrip().split("<tr")[-1].startswith(' class="oracle"><td>reference (oracle)')
  )
  markdown = (out / "README.md").read_text()
  assert markdown.index("## Who is best") < markdown.index("Generated by")
  assert f"| tendon-1 | **lstm** {best.figure} (oracle " in markdown
  assert f"| lstm | **{best.figure} (" not in markdown  # tendon-1 has no paper value: no bracket.
  assert f"| lstm | **{best.figure}** ★ |" in markdown


def test_a_video_column_only_where_a_record_has_a_video(contest, results, tmp_path):
  for folder, shown in ((contest, False), (results, True)):
    page = leaderboard.html_page.render(leaderboard.build(folder), folder, tmp_path)
    assert ('data-type="text">video</th>' in page) is shown


def test_an_aggregate_has_no_spread_to_show(real_record, tmp_path):
  # The IQM's chart once read "1.23 ± 0.000" in its tooltips: an IQM has an interval, no std.
  folder = tmp_path / "results"
  for task in aggregate.tasks():
    for agent, scale in (("smpl", 1.0), ("lstm", 0.5)):
      records.write(
        variant(real_record, agent, scale=scale, task=task), folder / f"{agent}-{task}.json"
      )
  board = leaderboard.build(folder)
  assert aggregate.views(board)
  page = leaderboard.html_page.render(board, folder, tmp_path)
  across = page[page.index('<section id="across-tasks">') : page.index('<section id="tasks">')]
  titles = [part.split("</title>")[0] for part in across.split("<title>")[1:]]
  assert len(titles) == 2 and all("±" not in title and "[" in title for title in titles), titles


def test_a_run_prints_micrometres_in_full(real_record):
  tiny = variant(real_record, scale=1e-5)  # Errors of micrometres, as the oracle's on reach.
  means = [seed["position_mm"]["mean"] for seed in tiny["per_seed"]]
  printed = run.table(tiny)
  assert 0 < np.mean(means) < 0.01 and "0.00 ± 0.00" not in printed
  assert metrics.mean_and_std(float(np.mean(means)), float(np.std(means))) in printed


def test_only_records_the_ledger_holds_as_they_are_are_verified(real_record, tmp_path):
  # A forged record (scores edited, its hash recomputed) is accepted as a record, never verified.
  folder = tmp_path / "results"
  records.write(variant(real_record, agent="smpl"), folder / "smpl.json")
  records.write(variant(real_record, agent="lstm"), folder / "lstm.json")
  loaded = dict(records.read_folder(folder))
  outcomes = {
    path.name: verified.Outcome(record, "2026-12-06T00:00:00+00:00", {"processor": "x"}, [0, 1])
    for path, record in loaded.items()
  }
  outcomes["lstm.json"].seeds = [0]  # Partly re-scored (--quick): not verified.
  verified.write(folder, outcomes)
  board = leaderboard.build(folder)
  assert board.verified == {"smpl.json"}
  records.write(variant(real_record, agent="smpl", scale=0.5), folder / "smpl.json")  # Forged.
  board = leaderboard.build(folder)
  assert board.verified == frozenset()
  leaderboard.write(board, folder, tmp_path / "site")
  rows = list(csv.DictReader((tmp_path / "site" / csv_table.FILE_NAME).open()))
  assert {row["agent"]: row["verified"] for row in rows} == {"smpl": "false", "lstm": "false"}
  page = (tmp_path / "site" / "index.html").read_text()
  assert page.count(f'title="{leaderboard.html_page.UNVERIFIED_TITLE}">no</td>') == 2


@pytest.mark.parametrize(
  "new,old,agrees",
  [
    ({"a": 6.686426005855, "n": 3}, {"a": 6.686426117895, "n": 3}, True),  # Two CPU kinds.
    ({"a": 6.69}, {"a": 6.68}, False),
    ({"a": 1.0, "n": 3}, {"a": 1.0, "n": 4}, False),
    ({"a": [1.0, 2.0]}, {"a": [1.0]}, False),
    ({"a": 1.0}, {"a": 1.0, "b": 0.0}, False),
    ({"a": 0.0}, {"a": 0.0}, True),
  ],
)
def test_a_rescored_figure_agrees_within_the_stated_tolerance(new, old, agrees):
  assert verified.agrees(new, old)[0] is agrees


def test_a_damaged_ledger_is_one_line(tmp_path):
  (tmp_path / "results").mkdir()
  verified.path_for(tmp_path / "results").write_text("[")
  with pytest.raises(ValueError, match=r"verified.json: not a verification ledger \("):
    leaderboard.build(tmp_path / "results")
