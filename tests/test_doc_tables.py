"""The results tables of README.md and docs/*.md are generated from the committed records
(``softbench.leaderboard.doc_tables``): every block is known and up to date, no typed table of
scores hides outside a block, and ``softbench leaderboard --write`` rewrites the blocks."""

import pathlib
import re
import shutil

import pytest

from softbench import cli
from softbench import leaderboard
from softbench import records
from softbench.leaderboard import doc_pages
from softbench.leaderboard import doc_tables
from softbench.records import fields as record_fields

ROOT = pathlib.Path(__file__).parent.parent
RESULTS = ROOT / "leaderboard" / "results"
# Tables of one-off measurements that no record holds (each page names the script or commit).
ONE_OFF_TABLE_HEADERS = (
  "| helpers |",  # docs/paper-comparison.md: reach with the other helper convention.
  "| robot, fault |",  # docs/faults.md: records of the fault experiment, in docs/faults/.
  "| stage |",  # docs/adaptive-activation.md: adaptive activation per stage.
  "| CPU |",  # docs/paper-comparison.md: SAC on two kinds of CPU (docs/analysis/sweep_vs_loop/sac).
  "| record (v0) |",  # docs/physics-versions.md: v0 records re-scored on v1 (rescore_on_v1.py).
)
EXP1S_RECORD = "smpl-exp1s-default-2026-11-24T041101Z.json"


@pytest.fixture(scope="module")
def board():
  return leaderboard.build(RESULTS)


@pytest.fixture(scope="module")
def pages() -> dict[pathlib.Path, str]:
  return {page: page.read_text(encoding="utf-8") for page in doc_pages.pages(RESULTS)}


def _block(name: str, body: str = "") -> str:
  return f"<!-- softbench:table {name} -->\n{body}<!-- /softbench:table -->\n"


def test_the_pages_are_the_readme_and_the_docs(pages):
  assert ROOT / "README.md" in pages
  assert ROOT / "docs" / "paper-comparison.md" in pages
  assert sum(len(doc_pages.blocks(text)) for text in pages.values()) >= len(doc_tables.TABLES)


def test_every_block_is_known_and_equals_what_the_records_give(pages, board):
  for page, text in pages.items():
    assert doc_pages.stale_blocks(text, board, str(page)) == [], (
      f"{page}: out of date; run softbench leaderboard --write"
    )


def test_every_named_table_appears_in_the_docs(pages):
  shown = {
    block.name.partition(doc_pages.PHYSICS_SEPARATOR)[0]
    for text in pages.values()
    for block in doc_pages.blocks(text)
  }
  assert shown == set(doc_tables.TABLES)


def test_no_typed_table_of_scores_outside_the_blocks(pages):
  for page, text in pages.items():
    lines = text.split("\n")
    inside = {line for block in doc_pages.blocks(text) for line in range(block.start, block.end)}
    header = None
    for number, line in enumerate(lines):
      if not line.lstrip().startswith("|"):
        header = None
        continue
      header = header or line.strip()
      if number not in inside and " ± " in line:
        assert header.startswith(ONE_OFF_TABLE_HEADERS), (
          f"{page}:{number + 1}: a typed table of scores; generate it (doc_tables.TABLES)"
        )


def test_an_unknown_table_fails(board):
  with pytest.raises(doc_tables.DocTableError, match=r"README.md:2: unknown table 'no-such'"):
    doc_pages.blocks("text\n" + _block("no-such"), "README.md")
  with pytest.raises(doc_tables.DocTableError, match="unknown table"):
    doc_pages.render("no-such", board)
  with pytest.raises(doc_tables.DocTableError, match="README.md:2: unknown physics version 'v9'"):
    doc_pages.blocks("text\n" + _block("headline-spiral@v9"), "README.md")


def test_a_block_names_the_physics_of_its_records(board):
  # NAME@v0 is the table of the v0 records, which every committed record before 2026-12-07 is.
  committed = records.read_folder(RESULTS)
  v0 = leaderboard.ranking.rank(
    [(path, record) for path, record in committed if record_fields.physics_of(record) == "v0"]
  )
  assert doc_pages.render("headline-spiral@v0", board) == doc_pages.render("headline-spiral", v0)


@pytest.mark.parametrize(
  "text,message",
  [
    (_block("headline-spiral").removesuffix("<!-- /softbench:table -->\n"), "never closed"),
    ("<!-- /softbench:table -->\n", "without an opening marker"),
    (_block("headline-spiral", "<!-- softbench:table headline-spiral -->\n"), "inside block"),
  ],
)
def test_a_malformed_block_fails(text, message):
  with pytest.raises(doc_tables.DocTableError, match=message):
    doc_pages.blocks(text)


def test_an_out_of_date_block_fails_and_rewriting_mends_it(pages, board):
  readme = pages[ROOT / "README.md"]
  generated = doc_pages.render("headline-spiral@v0", board)
  edited = readme.replace(generated, generated.replace("6.69 ± 1.77", "6.59 ± 1.77"), 1)
  assert edited != readme
  assert doc_pages.stale_blocks(edited, board) == ["headline-spiral@v0"]
  assert doc_pages.rewrite(edited, board) == readme
  emptied = readme.replace(generated, "", 1)
  assert doc_pages.stale_blocks(emptied, board) == ["headline-spiral@v0"]
  assert doc_pages.rewrite(emptied, board) == readme


@pytest.mark.parametrize(
  "shown,up_to_date",
  [
    ("| smpl | 6.69 ± 1.77 |", True),
    ("| smpl | 6.68 ± 1.78 |", True),  # A rounding flipped by a re-score on another CPU kind.
    ("| smpl | 6.67 ± 1.77 |", False),
    ("| smpl | 6.7 ± 1.77 |", False),
    ("| lstm | 6.69 ± 1.77 |", False),
    ("| smpl | 6.69 ± 1.77 | 3 |", False),
  ],
)
def test_a_figure_is_up_to_date_within_one_unit_of_its_last_digit(shown, up_to_date):
  assert doc_pages.same_figures(shown, "| smpl | 6.69 ± 1.77 |") is up_to_date


def _checkout_copy(root: pathlib.Path) -> pathlib.Path:
  """The pages and records of this checkout copied under ``root``; its results folder."""
  shutil.copy(ROOT / "README.md", root)
  shutil.copytree(ROOT / "docs", root / "docs", ignore=shutil.ignore_patterns("*.png", "*.mp4"))
  shutil.copytree(RESULTS, root / "leaderboard" / "results")
  return root / "leaderboard" / "results"


def test_a_record_made_again_on_another_machine_leaves_the_tables_up_to_date(tmp_path):
  # make run (or make run-v0) on another machine: the same setting re-scored, newer, with its own
  # wall time and figures that differ from the 8th significant digit on (another CPU kind).
  results = _checkout_copy(tmp_path)
  name = (
    "smpl-tendon-3-spiral-default-physics-2026-12-04T015317Z.json"  # A v0 record the docs show.
  )
  again = records.read(results / name)
  again.pop(records.INTEGRITY_FIELD)
  again.update(date="2026-12-31T23:59:59+00:00", wall_time_s=again["wall_time_s"] * 3 + 7)
  for seed in again["per_seed"]:
    for metric in ("position_mm", "orientation_deg", "normalised_tip_percent"):
      seed[metric] = {
        key: [value * (1 + 2e-8) for value in values] if isinstance(values, list) else values
        for key, values in seed[metric].items()
      }
      seed[metric]["mean"] *= 1 + 2e-8
  records.write(again, results / name.replace("2026-12-04T015317Z", "2026-12-31T235959Z"))
  board = leaderboard.build(results)
  assert board.of_physics("v0").groups, "the copy holds the v0 records"
  for page in doc_pages.pages(results):
    assert doc_pages.stale_blocks(page.read_text(encoding="utf-8"), board, str(page)) == [], page


def test_the_tables_use_the_records_population_std(board):
  # pneumatic-433 SMPL, paper profile, spiral: std over the 5 seeds with ddof 0 is 0.25 (ddof 1:
  # 0.28; a typed table once showed ddof 1).
  smpl = (
    "| smpl | 11.50 ± 0.33 (4.97) | 2.74 ± 0.32 (2.77) | 2.84 ± 0.31 (2.38) | 2.51 ± 0.25 (3.02) |"
  )
  assert smpl in doc_pages.render("overview-pneumatic-433-paper@v0", board)


def test_leaderboard_write_rewrites_the_blocks_of_the_checkout(tmp_path, capsys):
  results = tmp_path / "leaderboard" / "results"
  results.mkdir(parents=True)
  shutil.copy(RESULTS / EXP1S_RECORD, results)
  (tmp_path / "docs").mkdir()
  stale = "# Exp1S\n\n" + _block("exp1s-tendon-default", "| typed | 1.00 ± 0.10 |\n") + "\nEnd.\n"
  untouched = "# No tables\n"
  for path, text in (
    (tmp_path / "README.md", stale),
    (tmp_path / "docs" / "exp1s.md", stale),
    (tmp_path / "docs" / "other.md", untouched),
  ):
    path.write_text(text)
  cli.main(
    ["leaderboard", "--results", str(results), "--write", "--out", str(tmp_path / "leaderboard")]
  )
  board = leaderboard.build(results)
  expected = doc_pages.rewrite(stale, board)
  assert "20.00 ± 5.24 (1.49)" in expected and "typed" not in expected
  assert (tmp_path / "README.md").read_text() == expected
  assert (tmp_path / "docs" / "exp1s.md").read_text() == expected
  assert (tmp_path / "docs" / "other.md").read_text() == untouched
  printed = capsys.readouterr().out
  assert f"wrote {tmp_path / 'README.md'}" in printed
  assert f"wrote {tmp_path / 'docs' / 'other.md'}" not in printed
  # Up to date: nothing is written again.
  cli.main(
    ["leaderboard", "--results", str(results), "--write", "--out", str(tmp_path / "leaderboard")]
  )
  assert "README.md" not in capsys.readouterr().out.replace("leaderboard/README.md", "")


def test_another_results_folder_has_no_doc_pages(tmp_path):
  (tmp_path / "README.md").write_text(_block("no-such"))
  assert doc_pages.pages(tmp_path / "results") == []
  assert doc_pages.pages(tmp_path / "leaderboard" / "results") == [tmp_path / "README.md"]


README_MAX_LINES = 300  # A page a user reads in about five minutes (issue 26).
PROSE_COLUMNS = 100  # (characters) The code's line length (pyproject.toml), for written pages too.
LINK = re.compile(r"\]\(<?([^)<>\s]+)>?\)")


def test_the_readme_is_a_five_minute_read():
  lines = (ROOT / "README.md").read_text(encoding="utf-8").count("\n")
  assert lines <= README_MAX_LINES, f"README.md has {lines} lines; move detail to docs/"


@pytest.mark.parametrize("page", [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))])
def test_every_relative_link_names_a_file_of_the_checkout(page):
  targets = [link.split("#")[0] for link in LINK.findall(page.read_text(encoding="utf-8"))]
  local = [target for target in targets if target and "://" not in target]
  missing = [target for target in local if not (page.parent / target).exists()]
  assert missing == [], f"{page.name} links to files that do not exist: {missing}"


def _long_prose_lines(text: str) -> list[int]:
  """Numbers of the lines over ``PROSE_COLUMNS`` that a writer wraps: not code, tables, generated
  table blocks, HTML or images, and not a single unbreakable word."""
  long, fenced, generated = [], False, False
  for number, line in enumerate(text.splitlines(), start=1):
    if line.startswith("```"):
      fenced = not fenced
    elif line.startswith(("<!-- softbench:table", "<!-- /softbench:table")):
      generated = not line.startswith("<!-- /")
    elif not (fenced or generated) and len(line) > PROSE_COLUMNS:
      words = re.sub(r"^\s*([-*] |\d+\. )?", "", line).split()
      if not line.lstrip().startswith(("|", "<", "![")) and len(words) > 1:
        long.append(number)
  return long


@pytest.mark.parametrize("page", [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))])
def test_written_pages_wrap_their_prose_at_the_code_line_length(page):
  long = _long_prose_lines(page.read_text(encoding="utf-8"))
  assert long == [], f"{page.name}: lines over {PROSE_COLUMNS} characters: {long}"


def test_the_prose_width_check_finds_a_long_line_and_spares_code_and_tables():
  prose = "word " * 30
  code, table, generated = f"```sh\n{prose}\n```\n", f"| {prose} |\n", _block("x", prose + "\n")
  text = code + table + generated + f"- `one.unbreakable.word{'x' * 99}`\n"
  assert _long_prose_lines(text) == []
  assert _long_prose_lines(text + f"- {prose}\n") == [len(text.splitlines()) + 1]
