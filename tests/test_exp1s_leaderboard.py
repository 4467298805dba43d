"""Exp1S records (``softbench run --protocol exp1s``) on the leaderboard: schema, integrity and
consistency checks, the paper's layout and heat map on every page.

Records are built by hand (``handmade_exp1s``, no training). The end-to-end run that writes a
real one is ``tests/test_continual.py``.
"""

import copy
import json
import math
import pathlib

from handmade_exp1s import ROBOTS
from handmade_exp1s import exp1s_record
import jsonschema
import numpy as np
import pytest

from softbench import cli
from softbench import leaderboard
from softbench import records
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import html_page
from softbench.records import exp1s as exp1s_records
from softbench.runners import continual
from softbench.runners import run
from softbench.runners import run_settings


def write_raw(record: dict, path: pathlib.Path, reseal: bool = True) -> pathlib.Path:
  """Writes ``record`` unchecked; ``reseal`` first recomputes its hash, so that a check other
  than the hash has to refuse it."""
  record = dict(record)
  if reseal:
    record[records.INTEGRITY_FIELD] = records.content_sha256(record)
  path.write_text(json.dumps(record, indent=2))
  return path


def test_exp1s_schema_round_trip(tmp_path):
  record = exp1s_record()
  path = tmp_path / "exp1s.json"
  sealed = records.write(record, path)  # The path softbench run --protocol exp1s takes.
  assert sealed[records.INTEGRITY_FIELD] == records.content_sha256(record)
  assert path.read_text() == records.dumps(sealed)
  assert records.read(path) == sealed
  assert records.seal(sealed) == sealed
  assert sealed["version"] == exp1s_records.VERSION == 2
  schema = exp1s_records.schema()
  jsonschema.Draft202012Validator.check_schema(schema)
  jsonschema.validate(sealed, schema)
  with pytest.raises(jsonschema.ValidationError):  # Each kind's schema refuses the other kind.
    jsonschema.validate(sealed, records.schema())
  assert records.sections(sealed) == ()
  assert "forgetting matrix" in continual.table(sealed)  # The producer's own table reads it.


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


def _edit_number(record):
  record["per_seed"][0]["scores"]["open"]["circle"][2]["orientation_deg"] += 0.01


def _drop_configuration(record):
  record["per_seed"][1]["scores"]["closed"]["rectangle"].pop()


def _drop_task(record):
  del record["per_seed"][0]["scores"]["open"]["babbling"]


def _tip_not_from_position(record):
  record["per_seed"][0]["scores"]["open"]["babbling"][1]["normalised_tip_percent"] *= 1.5


def _not_square(record):
  record["per_seed"][0]["forgetting_tip_percent"].pop()


def _number_above_diagonal(record):
  record["per_seed"][1]["forgetting_model_pose_mse"][0][3] = 0.5


def _null_on_diagonal(record):
  record["per_seed"][0]["forgetting_tip_percent"][2][2] = None


def _last_row_differs(record):
  record["per_seed"][0]["forgetting_tip_percent"][-1][0] += 1.0


def _forgetting_task_dropped(record):
  record["tasks"].remove(continual.FORGETTING_TASK)
  for seed in record["per_seed"]:
    for loop in continual.LOOPS:
      del seed["scores"][loop][continual.FORGETTING_TASK]


MALFORMED = {
  "hand-edited number": (_edit_number, False, "does not match its sha256"),
  "old version": (
    _set(["version"], 1),
    True,
    "record version 1 is not read: it has no integrity hash",
  ),
  "newer version": (_set(["version"], 3), True, "this softbench reads version 2"),
  "NaN": (
    _set(["per_seed", 0, "scores", "closed", "spiral", 0, "position_mm"], math.nan),
    False,
    "position_mm: nan is not a finite number",
  ),
  "negative error": (
    _set(["per_seed", 1, "scores", "open", "circle", 0, "orientation_deg"], -1.0),
    True,
    "-1.0 is less than the minimum of 0",
  ),
  "integer beyond floats": (
    _set(["per_seed", 0, "scores", "closed", "spiral", 0, "position_mm"], 10**400),
    True,
    "is greater than the maximum of 1000000",
  ),
  "astronomical matrix entry": (
    _set(["per_seed", 0, "forgetting_model_pose_mse", 0, 0], 1e300),
    True,
    r"1e\+300 is greater than the maximum",
  ),
  "missing metric": (
    _set(["per_seed", 0, "scores", "closed", "circle", 0, "orientation_deg"], None),
    True,
    "'orientation_deg' is a required property",
  ),
  "unknown task": (_set(["tasks"], ["babbling", "juggle"]), True, "'juggle' is not one of"),
  "unknown loop": (_set(["per_seed", 0, "scores", "sideways"], {}), True, "sideways"),
  "unknown profile": (_set(["profile"], "huge"), True, "'huge' is not one of"),
  "profile settings": (
    _set(["profile_settings", "name"], "paper"),
    True,
    "is not the profile 'tiny'",
  ),
  "unknown robot": (
    _set(["robots"], ["tendon-0", *ROBOTS[1:]]),
    True,
    r"robots\[0\]: 'tendon-0' does not match",
  ),
  "loose robot name": (
    _set(["robots"], ["tendon-01", *ROBOTS[1:]]),
    True,
    r"robots\[0\]: 'tendon-01' does not match",
  ),
  "other protocol": (_set(["protocol"], "exp2s"), True, "'exp1s' was expected"),
  "extra scalar field": (_set(["score"], 3), True, "score: unknown field"),
  "seed count": (_set(["seeds"], 3), True, "seeds is 3 but per_seed has 2 entries"),
  "repeated seed": (_set(["per_seed", 1, "seed"], 0), True, "repeats a seed"),
  "configuration missing": (
    _drop_configuration,
    True,
    r"per_seed\[1\].scores.closed.rectangle has 4 entries for 5 "
    r"configurations",
  ),
  "task missing": (_drop_task, True, r"per_seed\[0\].scores.open has tasks"),
  "tip error": (
    _tip_not_from_position,
    True,
    r"scores.open.babbling\[1\]: normalised_tip_percent .* is not position_mm / "
    r"tendon-2's length",
  ),
  "matrix not square": (_not_square, True, "forgetting_tip_percent is not 5 x 5"),
  "number above the diagonal": (
    _number_above_diagonal,
    True,
    r"forgetting_model_pose_mse\[0\]\[3\] is 0.5; null expected",
  ),
  "null on the diagonal": (
    _null_on_diagonal,
    True,
    r"forgetting_tip_percent\[2\]\[2\] is None; a number expected",
  ),
  "forgetting row": (_last_row_differs, True, "last row .* is not the closed-loop spiral"),
  "forgetting task": (_forgetting_task_dropped, True, "lack spiral"),
  "date": (_set(["date"], "yesterday"), True, "not an ISO 8601 date"),
}


@pytest.mark.parametrize("case", MALFORMED)
def test_a_malformed_or_edited_exp1s_record_is_refused_with_one_line(case, tmp_path):
  change, reseal, message = MALFORMED[case]
  record = records.seal(exp1s_record())
  change(record)
  path = write_raw(record, tmp_path / "bad.json", reseal)
  with pytest.raises(records.RecordError, match=message) as raised:
    records.read(path)
  assert str(raised.value).startswith(f"{path}: ") and "\n" not in str(raised.value)


def test_writing_refuses_a_malformed_exp1s_record(tmp_path):
  record = exp1s_record()
  _drop_configuration(record)
  with pytest.raises(records.RecordError, match="has 4 entries for 5 configurations"):
    records.write(record, tmp_path / "record.json")
  assert not list(tmp_path.iterdir())


def test_the_cli_refuses_an_edited_exp1s_record(tmp_path, capsys):
  sealed = records.seal(exp1s_record())
  _edit_number(sealed)
  write_raw(sealed, tmp_path / "edited.json", reseal=False)
  assert cli.main(["leaderboard", "--results", str(tmp_path)]) == cli.EXIT_USAGE
  lines = capsys.readouterr().err.strip().splitlines()
  assert len(lines) == 1 and "edited.json: content does not match its sha256" in lines[0]


def test_paper_values_file():
  paper = exp1s_board.paper()
  assert "tab_exp1s_error" in paper["source"] and paper["robots"] == list(ROBOTS)
  for loop in continual.LOOPS:
    for task in continual.TASKS:
      for metric in exp1s_board.PAPER_METRICS:
        pairs = paper["scores"][loop][task][metric]
        assert len(pairs) == len(ROBOTS)
        assert all(len(pair) == 2 and 0 < pair[1] and 0 < pair[0] for pair in pairs)
  # Spot checks against the paper's table (Test Babbling and Spiral, configuration 1).
  assert paper["scores"]["closed"]["babbling"]["position_mm"][0] == [0.16, 0.03]
  assert paper["scores"]["open"]["spiral"]["orientation_deg"][4] == [1.95, 0.96]


@pytest.fixture(scope="module")
def run_record(tmp_path_factory) -> dict:
  """A 1-seed record of the zero agent on tendon-1 circle, as ``softbench run`` makes it."""
  with pytest.MonkeyPatch.context() as patch:
    patch.setenv("SOFTBENCH_HOME", str(tmp_path_factory.mktemp("exp1s_board_home")))
    settings = run_settings.settings("circle", "zero", "tendon-1", seeds=1, profile="tiny")
    return run.execute(settings, show_progress=False, workers=1)


@pytest.fixture
def results(run_record, tmp_path) -> pathlib.Path:
  """A folder with a run record and Exp1S records: two of profile tiny (one older), one of
  profile default, a two-configuration one, and one with an extra section."""
  folder = tmp_path / "results"
  made = {
    "exp1s-tiny-old.json": exp1s_record(date="2025-01-01T00:00:00+00:00", scale=0.5),
    "exp1s-tiny.json": exp1s_record(),
    "exp1s-default.json": exp1s_record(seeds=3, profile="default", scale=2.0),
    "exp1s-two.json": exp1s_record(robot_names=ROBOTS[:2]),
    "exp1s-fault.json": {**exp1s_record(), "fault": {"module": 1}},
    "run.json": run_record,
  }
  for name, record in made.items():
    records.write(record, folder / name)
  return folder


def test_exp1s_grouping(results):
  board = leaderboard.build(results)
  assert board.record_count == 6
  assert [group.title for group in board.groups] == ["tendon-1 · circle"]
  titles = [group.title for group in board.exp1s]
  assert titles == [
    "Exp1S · tendon-1, tendon-2",
    f"Exp1S · {', '.join(ROBOTS)}",
    f"Exp1S · {', '.join(ROBOTS)} (with fault)",
  ]
  full = board.exp1s[1]
  assert [entry.path.name for entry in full.entries] == ["exp1s-default.json", "exp1s-tiny.json"]
  assert [entry.path.name for entry in full.superseded] == ["exp1s-tiny-old.json"]


def test_exp1s_figures(results):
  entry = leaderboard.build(results).exp1s[1].entries[1]
  record = records.read(results / "exp1s-tiny.json")
  closed = exp1s_board.loop_table(entry, "closed")
  assert len(closed.rows) == 2 * len(ROBOTS) and closed.paper_rows == (1, 3, 5, 7, 9)
  values = [seed["scores"]["closed"]["circle"][2]["position_mm"] for seed in record["per_seed"]]
  column = closed.header.index("circle pos (mm)")
  assert closed.rows[4][column] == f"{np.mean(values):.2f} ± {np.std(values):.2f}"
  assert closed.rows[5][column] == "1.75 ± 0.85"  # The paper: circle, 3 modules, closed loop.
  forgetting = entry.forgetting()
  spiral = [
    [seed["scores"]["closed"]["spiral"][c]["normalised_tip_percent"] for seed in record["per_seed"]]
    for c in range(len(ROBOTS))
  ]
  assert forgetting[4] == pytest.approx([np.mean(values) for values in spiral], rel=1e-12)
  assert forgetting[1][2:] == [None] * 3


def test_pages_contain_every_exp1s_record(results, tmp_path, capsys):
  out = tmp_path / "site"
  assert cli.main(["leaderboard", "--results", str(results), "--write", "--out", str(out)]) == 0
  printed = capsys.readouterr().out
  markdown = (out / "README.md").read_text()
  page = (out / "index.html").read_text()
  for path in results.glob("*.json"):
    assert path.name in printed or path.name == "run.json"  # The printout names Exp1S files.
    assert f"(<../results/{path.name}>)" in markdown
    assert f'href="../results/{path.name}"' in page
  board = leaderboard.build(results)
  for group in board.exp1s:
    for text in (printed, markdown, page):
      assert group.title in text
    for entry in group.entries:
      for table in exp1s_board.tables(entry):
        for row in table.rows:
          for cell in row:
            assert cell in printed and cell in markdown and cell in page
  for text in (printed, markdown, page):
    assert "tendon-1 · circle" in text and "tab_exp1s_error" in text
  assert page.count('<table class="figures heat">') == 4  # One forgetting heat map per entry.
  shown_configurations = 2 + 5 + 5 + 5  # The two-configuration entry, then three of five.
  assert page.count('<tr class="paper">') == shown_configurations * len(continual.LOOPS)
  high = f"background:#{''.join(f'{c:02x}' for c in html_page._HEAT_HIGH)}"
  matrices = [entry.forgetting() for group in board.exp1s for entry in group.entries]
  largest = [
    max(value for row in matrix for value in row if value is not None) for matrix in matrices
  ]
  darkest = sum(row.count(value) for matrix, value in zip(matrices, largest) for row in matrix)
  assert page.count(high) == darkest  # The largest value of each matrix gets the darkest colour.
  assert page.count('<td class="empty"></td>') == sum(len(m) * (len(m) - 1) // 2 for m in matrices)
  assert "<link" not in page and "src=" not in page and "<script src" not in page


def test_regenerating_with_exp1s_records_is_deterministic(
  results, tmp_path, assert_regenerates_identically
):
  assert_regenerates_identically(results, tmp_path)


def test_a_record_is_checked_against_the_schema_of_its_format(tmp_path):
  """An Exp1S record that claims to be a run record is refused by the run record schema."""
  sealed = records.seal(exp1s_record())
  changed = copy.deepcopy(sealed)
  changed["format"] = records.FORMAT
  path = write_raw(changed, tmp_path / "mixed.json")
  with pytest.raises(records.RecordError, match="is a required property|unknown field"):
    records.read(path)
