"""The figure of an adaptive activation run, drawn from its result record alone: the position
error of every stage over targets (box plots with each target's point, the threshold dashed),
and the paths the target module's tip traced for the first targets, coloured by stage, beside
the all-modules-on path (grey)."""

import io
import pathlib

import matplotlib
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from softbench import storage

_PATH_PANELS = 4  # Path panels of the figure (the record keeps report.PLOTTED_TARGETS paths).
_DPI = 120


def _stage_colours(labels: list[str]) -> dict[str, tuple]:
  palette = matplotlib.colormaps["tab10"]
  return {label: palette(index % palette.N) for index, label in enumerate(labels)}


def _errors_panel(axes, adaptive: dict, colours: dict) -> None:
  summary = adaptive["summary"]
  labels = [entry["stage"] for entry in summary["stages"]]
  columns = [
    [
      stage["error_mm"]
      for target in adaptive["per_target"]
      for stage in target["stages"]
      if stage["stage"] == label
    ]
    for label in labels
  ]
  columns += [
    [target["final_error_mm"] for target in adaptive["per_target"]],
    [target["all_on_error_mm"] for target in adaptive["per_target"]],
  ]
  names = labels + ["final (adaptive)", "all modules on"]
  axes.boxplot(
    columns, tick_labels=names, showfliers=False, medianprops={"color": "black", "linewidth": 1.5}
  )
  for index, (name, values) in enumerate(zip(names, columns), start=1):
    colour = colours.get(name, "0.3")
    axes.scatter([index] * len(values), values, s=12, color=colour, alpha=0.7, zorder=3)
  axes.axhline(
    adaptive["threshold_mm"],
    color="0.4",
    linestyle="--",
    linewidth=1,
    label=f"threshold {adaptive['threshold_mm']:.1f} mm",
  )
  axes.set_ylabel("position error after settling (mm)")
  axes.set_title(f"error per stage over {adaptive['targets']} target(s)")
  axes.tick_params(axis="x", labelrotation=15)
  axes.legend(loc="upper right")


def _path_panel(axes, path: dict, colours: dict) -> None:
  points = path["path_mm"]
  start = 0
  for label, end in zip(path["stage_labels"], path["stage_ends"]):
    segment = points[start : end + 1]
    axes.plot(*zip(*segment), color=colours.get(label, "0.3"), linewidth=1.5)
    start = end
  axes.plot(*zip(*path["all_on_path_mm"]), color="0.6", linewidth=1, linestyle="--")
  axes.scatter(*[[value] for value in points[0]], color="black", s=15)
  axes.scatter(*[[value] for value in path["target_mm"]], color="red", marker="*", s=80)
  axes.set_aspect("equal")  # True geometry; few ticks on an axis the path hardly spans.
  for axis in (axes.xaxis, axes.yaxis, axes.zaxis):
    axis.set_major_locator(MaxNLocator(4))
  axes.set_title(f"target {path['target_seed']}", fontsize=9)
  axes.set_xlabel("x (mm)", fontsize=8)
  axes.set_ylabel("y (mm)", fontsize=8)
  axes.set_zlabel("z (mm)", fontsize=8)
  axes.tick_params(labelsize=7)


def figure(record: dict) -> Figure:
  """The figure of a record with an ``adaptive`` section."""
  adaptive = record["adaptive"]
  labels = [entry["stage"] for entry in adaptive["summary"]["stages"]]
  colours = _stage_colours(labels)
  paths = adaptive["paths"][:_PATH_PANELS]
  columns = max(len(paths), 1)
  fig = Figure(figsize=(3.6 * max(columns, 3), 8.5), layout="constrained")
  grid = fig.add_gridspec(2, columns, height_ratios=(1, 1.15))
  fig.suptitle(
    f"adaptive module activation: {record['agent']} on {record['robot']}, "
    f"module {adaptive['target_module']}, profile {record['profile']}"
  )
  _errors_panel(fig.add_subplot(grid[0, :]), adaptive, colours)
  for index, path in enumerate(paths):
    _path_panel(fig.add_subplot(grid[1, index], projection="3d"), path, colours)
  if paths:
    fig.legend(
      handles=_path_legend(labels, colours), loc="outside lower center", ncols=4, fontsize=8
    )
  return fig


def _path_legend(labels: list[str], colours: dict) -> list[Line2D]:
  stages = [Line2D([], [], color=colours[label], linewidth=1.5, label=label) for label in labels]
  return stages + [
    Line2D([], [], color="0.6", linestyle="--", linewidth=1, label="all modules on"),
    Line2D([], [], color="black", marker="o", linestyle="", markersize=4, label="start"),
    Line2D([], [], color="red", marker="*", linestyle="", markersize=9, label="target"),
  ]


def write(record: dict, path: pathlib.Path) -> pathlib.Path:
  """Draws the record's figure into the PNG ``path`` (atomically) and returns the path."""
  buffer = io.BytesIO()
  figure(record).savefig(buffer, format="png", dpi=_DPI)
  storage.write_atomically(path, buffer.getvalue())
  return pathlib.Path(path)
