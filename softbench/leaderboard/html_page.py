"""The leaderboard as one self-contained static page (``leaderboard/index.html``).

Inline CSS and JavaScript, no external resource: per robot and task a table whose columns sort
on a click, and a bar chart (inline SVG) per metric of the mean error with its bootstrap
interval as a whisker; links to each record and its video. Then the Exp1S records in the paper's
layout, the paper's rows beside ours, and the forgetting matrix as a colour heat map. The page
carries no time of its own, so the same records give the same bytes.
"""

import html
import pathlib

from softbench.leaderboard import aggregate
from softbench.leaderboard import exp1s_board
from softbench.leaderboard import figure_table
from softbench.leaderboard import links
from softbench.leaderboard import overview
from softbench.leaderboard import ranking

_CHART_WIDTH = 640  # (px) of an SVG bar chart.
_CHART_LABEL_WIDTH = 210  # (px) left of the bars, for the row's agent / profile / eval.
_CHART_VALUE_WIDTH = 70  # (px) right of the bars, for the mean.
_CHART_ROW_HEIGHT = 22  # (px) per bar.
_CHART_BAR_HEIGHT = 14  # (px)
_CHART_PAD = 6  # (px) above the first and below the last bar.
_HEAT_LOW = (247, 251, 255)  # (RGB) Heat-map colour of 0 %.
_HEAT_HIGH = (8, 48, 107)  # (RGB) Heat-map colour of the matrix's largest value.
_HEAT_LIGHT_TEXT_FROM = 0.5  # Fraction of the largest value from which a cell's text is white.

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 2rem auto; max-width: 72rem; padding: 0 1rem;
       color: #1b1f24; line-height: 1.45; }
h1 { font-size: 1.6rem; } h2 { font-size: 1.25rem; margin-top: 2.5rem; }
table { border-collapse: collapse; margin: 0.8rem 0; font-size: 0.9rem; }
th, td { border-bottom: 1px solid #d0d7de; padding: 0.3rem 0.6rem; text-align: left; }
th { background: #f3f5f7; cursor: pointer; user-select: none; white-space: nowrap; }
th[aria-sort="ascending"]::after { content: " \\25B2"; }
th[aria-sort="descending"]::after { content: " \\25BC"; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
td.figure { font-variant-numeric: tabular-nums; white-space: nowrap; }
.charts { display: flex; flex-wrap: wrap; gap: 1rem; }
figure { margin: 0; } figcaption { font-size: 0.85rem; color: #57606a; }
svg text { font-size: 11px; fill: #1b1f24; }
svg .bar { fill: #4c78a8; } svg .whisker { stroke: #1b1f24; stroke-width: 1.2; }
.note { color: #57606a; font-size: 0.9rem; }
table.figures th { cursor: default; } table.figures caption { text-align: left; font-size: 0.85rem;
  color: #57606a; caption-side: top; padding-bottom: 0.3rem; }
tr.paper td { color: #57606a; font-style: italic; border-bottom-color: #8c959f; }
table.heat td.figure { text-align: right; min-width: 4.5rem; }
.legend { display: inline-block; width: 8rem; height: 0.7rem; vertical-align: middle;
          border: 1px solid #d0d7de; }
"""

_SCRIPT = """
function sortTable(table, header, column) {
  var ascending = header.getAttribute("aria-sort") !== "ascending";
  table.querySelectorAll("th").forEach(function (th) { th.removeAttribute("aria-sort"); });
  header.setAttribute("aria-sort", ascending ? "ascending" : "descending");
  var numeric = header.dataset.type === "number";
  var key = function (row) {
    var cell = row.cells[column];
    var value = cell.dataset.value !== undefined ? cell.dataset.value : cell.textContent;
    if (!numeric) return value;
    return value === "" ? Infinity : parseFloat(value);
  };
  var body = table.tBodies[0];
  var rows = Array.prototype.slice.call(body.rows);
  rows.sort(function (a, b) {
    var x = key(a), y = key(b);
    var order = x < y ? -1 : (x > y ? 1 : 0);
    return ascending ? order : -order;
  });
  rows.forEach(function (row) { body.appendChild(row); });
}
document.querySelectorAll("table.sortable").forEach(function (table) {
  table.querySelectorAll("th").forEach(function (header, column) {
    header.tabIndex = 0;
    header.addEventListener("click", function () { sortTable(table, header, column); });
    header.addEventListener("keydown", function (event) {
      if (event.key === "Enter" || event.key === " ") {
        event.preventDefault();
        sortTable(table, header, column);
      }
    });
  });
});
"""


def _e(text: object) -> str:
  return html.escape(str(text), quote=True)


def _px(value: float) -> str:
  return f"{value:.1f}"


def _chart(group: ranking.Group, metric: str) -> str:
  """Horizontal bars of the mean of ``metric`` per row, whiskers over the bootstrap interval."""
  rows = [entry for entry in group.entries if metric in entry.estimates]
  bars_width = _CHART_WIDTH - _CHART_LABEL_WIDTH - _CHART_VALUE_WIDTH
  height = 2 * _CHART_PAD + _CHART_ROW_HEIGHT * len(rows)
  highest = max(
    max([estimate.mean, *(estimate.interval or ())])
    for estimate in (entry.estimates[metric] for entry in rows)
  )
  scale = bars_width / highest if highest > 0 else 0.0
  label = ranking.METRIC_LABELS[metric]
  parts = [
    f'<svg xmlns="http://www.w3.org/2000/svg" width="{_CHART_WIDTH}" height="{height}" '
    f'viewBox="0 0 {_CHART_WIDTH} {height}" role="img" aria-label="{_e(label)}">'
  ]
  for index, entry in enumerate(rows):
    estimate = entry.estimates[metric]
    top = _CHART_PAD + index * _CHART_ROW_HEIGHT
    middle = top + _CHART_ROW_HEIGHT / 2
    bar_top = middle - _CHART_BAR_HEIGHT / 2
    parts.append(f"<g><title>{_e(entry.label)}: {_e(ranking.cell(estimate))}</title>")
    parts.append(
      f'<text x="{_CHART_LABEL_WIDTH - 6}" y="{_px(middle + 4)}" '
      f'text-anchor="end">{_e(entry.label)}</text>'
    )
    parts.append(
      f'<rect class="bar" x="{_CHART_LABEL_WIDTH}" y="{_px(bar_top)}" '
      f'width="{_px(estimate.mean * scale)}" height="{_CHART_BAR_HEIGHT}"/>'
    )
    if estimate.interval is not None:
      low, high = (_CHART_LABEL_WIDTH + value * scale for value in estimate.interval)
      parts.append(
        f'<path class="whisker" d="M{_px(low)} {_px(middle)}H{_px(high)}'
        f"M{_px(low)} {_px(middle - 4)}V{_px(middle + 4)}"
        f'M{_px(high)} {_px(middle - 4)}V{_px(middle + 4)}"/>'
      )
    parts.append(
      f'<text x="{_CHART_WIDTH - _CHART_VALUE_WIDTH + 6}" y="{_px(middle + 4)}">'
      f"{_e(ranking.number(estimate.mean))}</text></g>"
    )
  parts.append("</svg>")
  caption = (
    f"{label}, mean over seeds (lower is better); whiskers: {ranking.CONFIDENCE:.0%} bootstrap CI"
  )
  return f"<figure>{''.join(parts)}<figcaption>{_e(caption)}</figcaption></figure>"


def _table(group: ranking.Group, out: pathlib.Path) -> str:
  columns = (
    [("#", "number"), ("agent", "text"), ("profile", "text"), ("eval", "text"), ("seeds", "number")]
    + [(ranking.METRIC_LABELS[name], "number") for name in group.metrics]
    + [("video", "text"), ("record", "text")]
  )
  head = "".join(f'<th scope="col" data-type="{kind}">{_e(name)}</th>' for name, kind in columns)
  body = []
  for place, entry in enumerate(group.entries, start=1):
    cells = [
      f'<td class="number">{place}</td>',
      *(f"<td>{_e(value)}</td>" for value in entry.shown_setting),
      f'<td class="number">{entry.record["seeds"]}</td>',
    ]
    for name in group.metrics:
      estimate = entry.estimates.get(name)
      value = "" if estimate is None else repr(estimate.mean)
      cells.append(f'<td class="figure" data-value="{value}">{_e(ranking.cell(estimate))}</td>')
    video = links.video(entry, out)
    cells.append(f'<td><a href="{_e(video)}">video</a></td>' if video else "<td>-</td>")
    cells.append(f'<td><a href="{_e(links.record(entry, out))}">{_e(entry.path.name)}</a></td>')
    body.append(f"<tr>{''.join(cells)}</tr>")
  return (
    f'<table class="sortable"><thead><tr>{head}</tr></thead><tbody>{"".join(body)}</tbody></table>'
  )


def _superseded(entries, setting: str, out: pathlib.Path) -> str:
  """The note listing records superseded by a newer one of the same ``setting``."""
  items = "".join(
    f'<li><a href="{_e(links.record(entry, out))}">{_e(entry.path.name)}</a> '
    f"({_e(entry.label)}, {_e(entry.record['date'])})</li>"
    for entry in entries
  )
  return (
    f'<p class="note">Superseded by a newer record of the same {_e(setting)}:</p>'
    f'<ul class="note">{items}</ul>'
  )


def _group(group: ranking.Group, out: pathlib.Path) -> str:
  parts = [
    f'<section id="{_e(group.anchor)}"><h2>{_e(group.title)}</h2>',
    _table(group, out),
    '<div class="charts">' + "".join(_chart(group, name) for name in group.metrics) + "</div>",
  ]
  if group.superseded:
    parts.append(_superseded(group.superseded, "agent, profile and eval mode", out))
  parts.append("</section>")
  return "\n".join(parts)


def _figure_table(table: figure_table.Table) -> str:
  head = "".join(f'<th scope="col">{_e(name)}</th>' for name in table.header)
  body = []
  for index, row in enumerate(table.rows):
    cells = "".join(
      f"<td>{_e(value)}</td>"
      if column < table.label_columns
      else f'<td class="figure">{_e(value)}</td>'
      for column, value in enumerate(row)
    )
    body.append(
      f'<tr class="paper">{cells}</tr>' if index in table.paper_rows else f"<tr>{cells}</tr>"
    )
  return (
    f'<table class="figures"><caption>{_e(table.caption)}</caption><thead><tr>{head}</tr>'
    f"</thead><tbody>{''.join(body)}</tbody></table>"
  )


def _rgb(colour: tuple[float, ...]) -> str:
  return "#" + "".join(f"{round(channel):02x}" for channel in colour)


def _heat_map(entry: exp1s_board.Entry) -> str:
  """The forgetting matrix with each cell coloured by its value (light 0, dark the largest)."""
  table = exp1s_board.forgetting_table(entry)
  values = entry.forgetting()
  highest = max(value for row in values for value in row if value is not None)
  head = "".join(f'<th scope="col">{_e(name)}</th>' for name in table.header)
  body = []
  for row, texts in zip(values, table.rows):
    cells = [f"<td>{_e(texts[0])}</td>"]
    for value, text in zip(row, texts[1:]):
      if value is None:
        cells.append('<td class="empty"></td>')  # Not yet learned at this stage.
        continue
      share = value / highest if highest > 0 else 0.0
      colour = _rgb(tuple(low + share * (high - low) for low, high in zip(_HEAT_LOW, _HEAT_HIGH)))
      ink = "#ffffff" if share >= _HEAT_LIGHT_TEXT_FROM else "#1b1f24"
      cells.append(
        f'<td class="figure" style="background:{colour};color:{ink}" '
        f'data-value="{value!r}">{_e(text)}</td>'
      )
    body.append(f"<tr>{''.join(cells)}</tr>")
  legend = (
    f'<p class="note">Colour: 0 % <span class="legend" style="background:linear-gradient('
    f'to right,{_rgb(_HEAT_LOW)},{_rgb(_HEAT_HIGH)})"></span> '
    f"{_e(ranking.number(highest))} % (the largest value).</p>"
  )
  return (
    f'<table class="figures heat"><caption>{_e(table.caption)}</caption><thead><tr>{head}'
    f"</tr></thead><tbody>{''.join(body)}</tbody></table>{legend}"
  )


def _overviews(views: tuple[overview.Overview, ...]) -> list[str]:
  if not views:
    return []
  return [
    *(
      f'<section id="{_e(view.anchor)}"><h2>{_e(view.title)}</h2>'
      f"{_figure_table(view.table)}</section>"
      for view in views
    ),
    f'<p class="note">{_e(overview.about_paper())}</p>',
  ]


def _across(views: tuple[aggregate.View, ...]) -> list[str]:
  return [
    f'<section id="{_e(view.anchor)}"><h2>{_e(view.title)}</h2>'
    f"{_figure_table(view.table)}"
    f'<img src="{_e(view.image)}" alt="{_e(view.title)}: performance profiles" width="640">'
    "</section>"
    for view in views
  ]


def _exp1s_group(group: exp1s_board.Group, out: pathlib.Path) -> str:
  parts = [f'<section id="{_e(group.anchor)}"><h2>{_e(group.title)}</h2>']
  for entry in group.entries:
    parts.append(f"<h3>{_e(entry.label)}</h3>")
    parts.append(
      f"<p>{_e(exp1s_board.describe(entry))}; record "
      f'<a href="{_e(links.record(entry, out))}">{_e(entry.path.name)}</a>.</p>'
    )
    parts += [_figure_table(table) for table in exp1s_board.score_tables(entry)]
    parts.append(_heat_map(entry))
  if group.superseded:
    parts.append(_superseded(group.superseded, "agent and profile", out))
  parts += [f'<p class="note">{_e(exp1s_board.about_paper())}</p>', "</section>"]
  return "\n".join(parts)


def render(board: ranking.Leaderboard, results: pathlib.Path, out: pathlib.Path) -> str:
  """The page, with links relative to the folder ``out`` it is written to."""
  results_link = links.relative(pathlib.Path(results), out)
  views = overview.overviews(board)
  across = aggregate.views(board)
  intro = [
    f'<p class="note">Generated by <code>softbench leaderboard --write</code> from the '
    f'result records in <a href="{_e(results_link)}">{_e(results_link)}</a>.</p>'
  ]
  if board.record_count:
    intro.append(
      f"<p>{board.record_count} record(s), the newest from {_e(board.latest_date)}. Each row "
      "is the newest record of one agent, profile and eval mode, ranked by position error "
      "(lower is better; click a column to sort). Figures: mean ± standard deviation over "
      "seeds of the episode's error averaged over the scored modules, "
      f"[{ranking.CONFIDENCE:.0%} percentile bootstrap confidence interval of the mean, "
      f"{ranking.BOOTSTRAP_RESAMPLES:,} resamples] with {ranking.MIN_SEEDS_FOR_INTERVAL} or "
      "more seeds. How to submit an agent: the <em>Leaderboard</em> section of softbench's "
      "README.</p>"
    )
    if board.exp1s:
      intro.append(f"<p>{_e(exp1s_board.explanation())}</p>")
    intro.append(
      "<nav><ul>"
      + "".join(
        f'<li><a href="#{_e(group.anchor)}">{_e(group.title)}</a></li>'
        for group in (*views, *across, *board.groups, *board.exp1s)
      )
      + "</ul></nav>"
    )
  else:
    intro.append(
      "<p>No result records yet. Make one with <code>softbench run</code> (for "
      "example <code>softbench run --task spiral --agent smpl</code>), then run "
      "<code>softbench leaderboard --write</code>.</p>"
    )
  return "\n".join(
    [
      "<!DOCTYPE html>",
      '<html lang="en">',
      "<head>",
      '<meta charset="utf-8">',
      '<meta name="viewport" content="width=device-width, initial-scale=1">',
      "<title>softbench leaderboard</title>",
      f"<style>{_STYLE}</style>",
      "</head>",
      "<body>",
      "<h1>softbench leaderboard</h1>",
      *intro,
      *_overviews(views),
      *_across(across),
      *(_group(group, out) for group in board.groups),
      *(_exp1s_group(group, out) for group in board.exp1s),
      f"<script>{_SCRIPT}</script>",
      "</body>",
      "</html>",
      "",
    ]
  )
