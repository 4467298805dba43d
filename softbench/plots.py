"""Plots of runs (matplotlib, drawn off-screen with Agg, saved as PNG through
``storage.write_atomically``).

- ``tracking_paths``: target and achieved 3-D tip paths of one episode, a panel per module.
- ``tracking_errors``: position (and orientation) error over the control steps of episodes,
  a line per module and seed.
- ``forgetting_matrix``: the continual-learning heat map of Exp1S, normalised tip error of every
  configuration after every training stage.
- ``save_run_plots``: the first two for a ``softbench run``, next to its result record.
"""

import io
import math
import pathlib
from typing import TYPE_CHECKING
from typing import Sequence

import matplotlib
from matplotlib import colors as mpl_colors
from matplotlib import ticker
from matplotlib.figure import Figure
import numpy as np

from softbench import episodes
from softbench import metrics
from softbench import robots
from softbench import storage

if TYPE_CHECKING:
  from softbench.robots.base import SoftArm

DPI = 110  # (dots per inch) of saved figures.
PANEL_INCHES = 4.0  # Width and height of one 3-D path panel.
MAX_PANEL_COLUMNS = 3
MIN_AXIS_SHARE = 0.4  # 3-D panels scale x, y and z (mm) alike, but stretch an axis spanning
# less than this share of the largest span to it, so that a flat path keeps readable ticks.
OTHER_SEED_ALPHA = 0.35  # Lines of seeds after the first are drawn fainter.
_TARGET_COLOUR = "0.25"
_NOT_SEEN_COLOUR = "0.85"
_HEAT_MAP = "viridis"


def _save(figure: Figure, path: str | pathlib.Path) -> pathlib.Path:
  path = pathlib.Path(path)
  buffer = io.BytesIO()
  figure.savefig(buffer, format="png", dpi=DPI)
  storage.write_atomically(path, buffer.getvalue())
  return path


def _module_colours(robot: "SoftArm | None", modules: Sequence[int]) -> list:
  """The colour each module is drawn in (as in videos), or matplotlib's cycle without a robot."""
  if robot is None:
    return [f"C{index}" for index in range(len(modules))]
  from softbench.rendering import scene  # The robot's model (MuJoCo), not needed by other plots.

  colours = scene.module_colours(robot.compile(), robot.num_modules)
  return [tuple(colours[module - 1][:3]) for module in modules]


def tracking_paths(
  episode: episodes.Episode,
  path: str | pathlib.Path,
  title: str = "",
  robot: "SoftArm | None" = None,
) -> pathlib.Path:
  """Saves target (dashed) and achieved (solid) tip paths in mm, a 3-D panel per scored module,
  starting at the pose before the first step. A target held all episode is drawn as a star.
  Axes share one scale (see ``MIN_AXIS_SHARE``)."""
  modules = episode.scored_modules
  colours = _module_colours(robot, modules)
  columns = min(len(modules), MAX_PANEL_COLUMNS)
  rows = math.ceil(len(modules) / columns)
  figure = Figure(
    figsize=(PANEL_INCHES * columns, PANEL_INCHES * rows * 0.8 + 0.4), layout="constrained"
  )
  errors = metrics.position_error_mm(episode.achieved[..., :3], episode.targets[..., :3])
  for index, module in enumerate(modules):
    axes = figure.add_subplot(rows, columns, index + 1, projection="3d")
    achieved = np.concatenate([episode.poses[:1, module - 1, :3], episode.achieved[:, index, :3]])
    achieved = achieved * metrics.MM_PER_M
    targets = episode.targets[:, index, :3] * metrics.MM_PER_M
    if np.ptp(targets, axis=0).max() == 0:
      axes.scatter(*targets[0], marker="*", s=120, color=_TARGET_COLOUR, label="target")
    else:
      axes.plot(*targets.T, "--", color=_TARGET_COLOUR, linewidth=1.0, label="target")
    axes.plot(*achieved.T, "-", color=colours[index], linewidth=1.6, label="achieved")
    axes.scatter(*achieved[0], marker="o", s=20, color=colours[index])
    spans = np.ptp(np.concatenate([achieved, targets]), axis=0)
    axes.set_box_aspect(np.maximum(spans, MIN_AXIS_SHARE * max(spans.max(), 1e-6)), zoom=0.85)
    for axis, name in zip((axes.xaxis, axes.yaxis, axes.zaxis), "xyz"):
      axis.set_major_locator(ticker.MaxNLocator(3 if name == "z" else 4))
      axis.set_label_text(f"{name} (mm)")
    axes.tick_params(axis="z", pad=6)
    axes.zaxis.labelpad = 12
    axes.set_title(f"module {module}: mean error {errors[:, index].mean():.2f} mm", fontsize=10)
    if index == 0:
      axes.legend(loc="upper left", fontsize=8)
  if title:
    figure.suptitle(title)
  return _save(figure, path)


def tracking_errors(
  episodes: Sequence[episodes.Episode],
  path: str | pathlib.Path,
  title: str = "",
  robot: "SoftArm | None" = None,
) -> pathlib.Path:
  """Saves position error (mm), and orientation error (deg) for 6-D targets, over control steps:
  a line per module and episode (seed), the first episode's drawn solid, the others fainter."""
  if not episodes:
    raise ValueError("no episodes to plot")
  modules = episodes[0].scored_modules
  colours = _module_colours(robot, modules)
  with_orientation = episodes[0].targets.shape[-1] == 6
  panels = [
    (
      "position error (mm)",
      lambda e: metrics.position_error_mm(e.achieved[..., :3], e.targets[..., :3]),
    )
  ]
  if with_orientation:
    panels.append(
      ("orientation error (deg)", lambda e: metrics.orientation_error_deg(e.achieved, e.targets))
    )
  figure = Figure(figsize=(8.0, 2.8 * len(panels) + 0.6), layout="constrained")
  all_axes = figure.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
  for axes, (label, error) in zip(all_axes, panels):
    for seed, episode in enumerate(episodes):
      values = error(episode)
      steps = np.arange(1, len(values) + 1)
      for index, module in enumerate(modules):
        axes.plot(
          steps,
          values[:, index],
          color=colours[index],
          alpha=1.0 if seed == 0 else OTHER_SEED_ALPHA,
          linewidth=1.4 if seed == 0 else 0.9,
          label=f"module {module}" if seed == 0 else None,
        )
    axes.set_ylabel(label)
    axes.set_ylim(bottom=0)
    axes.grid(alpha=0.3)
  all_axes[0].legend(loc="upper right", fontsize=8, ncols=min(len(modules), 5))
  all_axes[-1].set_xlabel(
    "control step"
    + (f" (lines: {len(episodes)} seeds, the first solid)" if len(episodes) > 1 else "")
  )
  if title:
    figure.suptitle(title)
  return _save(figure, path)


def forgetting_matrix(
  matrix: np.ndarray,
  configurations: Sequence[str],
  path: str | pathlib.Path,
  stage_labels: Sequence[str] | None = None,
  title: str = "normalised tip error (%) after each training stage",
) -> pathlib.Path:
  """Saves the forgetting heat map: normalised tip error (%) of every configuration (columns)
  after every training stage (rows), each cell labelled; NaN entries (a configuration not yet
  seen) are drawn blank and marked "not seen".

  Args:
    matrix: (stages, configurations) errors in %, NaN where not evaluated.
    configurations: Column names, e.g. ``tendon-1`` ... ``tendon-5``.
    stage_labels: Row names (default ``stage 1`` ...).

  Raises:
    ValueError: a matrix that is not 2-D, does not match the labels, has no finite entry, or has
      a negative or infinite entry (one line).
  """
  matrix = np.asarray(matrix, dtype=float)
  if matrix.ndim != 2 or matrix.shape[0] == 0:
    raise ValueError(
      f"forgetting matrix must be (stages, configurations), got shape {matrix.shape}"
    )
  if matrix.shape[1] != len(configurations):
    raise ValueError(
      f"forgetting matrix has {matrix.shape[1]} columns but {len(configurations)} configurations"
    )
  stage_labels = (
    list(stage_labels)
    if stage_labels is not None
    else [f"stage {index + 1}" for index in range(matrix.shape[0])]
  )
  if len(stage_labels) != matrix.shape[0]:
    raise ValueError(
      f"forgetting matrix has {matrix.shape[0]} stages but {len(stage_labels)} stage labels"
    )
  seen = ~np.isnan(matrix)
  if not seen.any():
    raise ValueError("forgetting matrix has no evaluated entry (all NaN)")
  if np.any(np.isinf(matrix)) or np.any(matrix[seen] < 0):
    raise ValueError("forgetting matrix entries must be finite and non-negative, or NaN")
  figure = Figure(
    figsize=(1.2 * matrix.shape[1] + 2.8, 0.7 * matrix.shape[0] + 1.6), layout="constrained"
  )
  axes = figure.add_subplot()
  colour_map = matplotlib.colormaps[_HEAT_MAP].with_extremes(bad=_NOT_SEEN_COLOUR)
  norm = mpl_colors.Normalize(vmin=0.0, vmax=max(float(matrix[seen].max()), 1e-9))
  image = axes.imshow(np.ma.masked_invalid(matrix), cmap=colour_map, norm=norm, aspect="auto")
  for (row, column), value in np.ndenumerate(matrix):
    if np.isnan(value):
      axes.text(column, row, "not seen", ha="center", va="center", fontsize=8, color="0.4")
    else:
      shade = np.mean(colour_map(norm(value))[:3])
      axes.text(
        column,
        row,
        f"{value:.2f}",
        ha="center",
        va="center",
        fontsize=9,
        color="black" if shade > 0.5 else "white",
      )
  axes.set_xticks(range(matrix.shape[1]), list(configurations))
  axes.set_yticks(range(matrix.shape[0]), stage_labels)
  axes.set_xlabel("configuration evaluated")
  axes.set_ylabel("after training")
  figure.colorbar(image, ax=axes, label="normalised tip error (%)")
  axes.set_title(title, fontsize=10)
  return _save(figure, path)


def run_plot_paths(record_path: str | pathlib.Path) -> tuple[pathlib.Path, pathlib.Path]:
  """Where ``save_run_plots`` puts the path and error plots of a result record."""
  record_path = pathlib.Path(record_path)
  stem = record_path.with_suffix("")
  return (stem.with_name(f"{stem.name}-paths.png"), stem.with_name(f"{stem.name}-error.png"))


def save_run_plots(
  record_path: str | pathlib.Path, record: dict, episodes: Sequence[episodes.Episode]
) -> tuple[pathlib.Path, pathlib.Path]:
  """Saves the first episode's (seed 0's) tip paths and every episode's errors over time next to
  the result record ``record`` (``softbench.runners.run``): ``<record stem>-paths.png`` and
  ``<record stem>-error.png``."""
  robot = robots.make(record["robot"])
  title = f"{record['agent']} on {record['task']} ({record['robot']}), {record['profile']} profile"
  paths_png, error_png = run_plot_paths(record_path)
  tracking_paths(episodes[0], paths_png, f"{title}, seed 0", robot)
  tracking_errors(episodes, error_png, title, robot)
  return paths_png, error_png


def performance_profiles(
  curves: dict[str, np.ndarray], thresholds: np.ndarray, title: str, path: str | pathlib.Path
) -> pathlib.Path:
  """Saves performance profiles (rliable's): for each agent (``curves``' keys, in order) the share
  of runs whose normalised tip error is at most each of ``thresholds`` (% of the arm's length,
  drawn on a log axis)."""
  figure = Figure(figsize=(6.4, 4.0))
  axes = figure.add_subplot()
  for index, (agent, shares) in enumerate(curves.items()):
    axes.step(thresholds, shares, where="post", label=agent, color=f"C{index % 10}")
  axes.set_xscale("log")
  axes.set_ylim(-0.02, 1.02)
  axes.set_xlabel("normalised tip error threshold τ (% of the arm's length)")
  axes.set_ylabel("share of runs with error ≤ τ")
  axes.set_title(title, fontsize="medium")
  axes.grid(True, which="major", alpha=0.3)
  axes.legend(fontsize="small", loc="upper left")
  figure.tight_layout()
  return _save(figure, path)
