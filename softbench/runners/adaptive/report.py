"""The numbers of an adaptive activation run: the ``adaptive`` section of its result record, and
the printed table. Distributions are over targets: median, interquartile range, mean and
standard deviation (population)."""

import collections

import numpy as np

from softbench.runners.adaptive import experiment
from softbench.runners.adaptive import procedure

PLOTTED_TARGETS = 4  # Targets whose paths the record keeps (and the plot draws).
_DECIMALS = 3  # Rounding of positions in the record (mm).


def distribution(values) -> dict:
  """Median, quartiles, mean, standard deviation and count of ``values``."""
  values = np.asarray(values, dtype=float)
  q25, median, q75 = np.percentile(values, [25, 50, 75])
  return {
    "median": float(median),
    "q25": float(q25),
    "q75": float(q75),
    "mean": float(np.mean(values)),
    "std": float(np.std(values)),
    "count": int(values.size),
  }


def modules_label(modules) -> str:
  """``(1, 2)`` as ``1+2``."""
  return "+".join(str(module) for module in modules)


def _target_entry(outcome: experiment.TargetOutcome) -> dict:
  return {
    "target_seed": outcome.target_seed,
    "target_mm": np.round(outcome.target_mm, _DECIMALS).tolist(),
    "stages": [
      {
        "stage": result.stage.label,
        "active": list(result.stage.active),
        "error_mm": result.error,
        "kept": result.kept,
      }
      for result in outcome.stages
    ],
    "final_active": list(outcome.final_active),
    "final_error_mm": outcome.final_error_mm,
    "all_on_error_mm": outcome.all_on_error_mm,
    "effort": outcome.effort,
    "all_on_effort": outcome.all_on_effort,
    "effort_saved_percent": outcome.effort_saved_percent,
    "holding_effort": outcome.holding_effort,
    "all_on_holding_effort": outcome.all_on_holding_effort,
    "holding_effort_saved_percent": outcome.holding_effort_saved_percent,
  }


def _path_entry(outcome: experiment.TargetOutcome) -> dict:
  return {
    "target_seed": outcome.target_seed,
    "target_mm": np.round(outcome.target_mm, _DECIMALS).tolist(),
    "stage_labels": [result.stage.label for result in outcome.stages],
    "stage_ends": list(outcome.stage_ends),
    "path_mm": np.round(outcome.path_mm, _DECIMALS).tolist(),
    "all_on_path_mm": np.round(outcome.all_on_path_mm, _DECIMALS).tolist(),
  }


def section(
  outcomes: list[experiment.TargetOutcome],
  num_modules: int,
  module: int,
  threshold_mm: float,
  stages: experiment.Timing,
  control_timestep: float,
  helpers: str,
) -> dict:
  """The record's ``adaptive`` section: settings, every target, and the distributions."""
  by_stage = collections.defaultdict(list)
  for outcome in outcomes:
    for result in outcome.stages:
      by_stage[result.stage.label].append(result.error)
  labels = procedure.ActivationProcedure(num_modules, module, threshold_mm).labels
  chosen = collections.Counter(modules_label(outcome.final_active) for outcome in outcomes)
  return {
    "agent_seed": experiment.AGENT_SEED,
    "target_module": module,
    "targets": len(outcomes),
    "helpers": helpers,
    "threshold_mm": threshold_mm,
    "threshold_fraction": experiment.THRESHOLD_FRACTION,
    "stage_s": stages.stage_steps * control_timestep,
    "settle_s": stages.settle_steps * control_timestep,
    "stage_steps": stages.stage_steps,
    "settle_steps": stages.settle_steps,
    "effort": "sum over control steps of the squared action entries",
    "summary": {
      "stages": [
        {"stage": label, "error_mm": distribution(by_stage[label])}
        for label in labels
        if by_stage[label]
      ],
      "final_error_mm": distribution([outcome.final_error_mm for outcome in outcomes]),
      "all_on_error_mm": distribution([outcome.all_on_error_mm for outcome in outcomes]),
      "effort_saved_percent": distribution([outcome.effort_saved_percent for outcome in outcomes]),
      "holding_effort_saved_percent": distribution(
        [outcome.holding_effort_saved_percent for outcome in outcomes]
      ),
      "final_active": dict(sorted(chosen.items())),
    },
    "per_target": [_target_entry(outcome) for outcome in outcomes],
    "paths": [_path_entry(outcome) for outcome in outcomes[:PLOTTED_TARGETS]],
  }


def _row(name: str, values: dict) -> str:
  return (
    f"{name:<26}{values['count']:>8}{values['median']:>9.2f}"
    f"{values['q25']:>9.2f} .. {values['q75']:<7.2f}"
    f"{values['mean']:>9.2f} ± {values['std']:<7.2f}"
  )


def table(record: dict) -> str:
  """The printed summary of a record with an ``adaptive`` section."""
  adaptive = record["adaptive"]
  summary = adaptive["summary"]
  module = adaptive["target_module"]
  lines = [
    f"adaptive module activation: {record['agent']} (agent seed {adaptive['agent_seed']}) on "
    f"reach ({record['robot']}), module {module}, {adaptive['targets']} target(s), profile "
    f"{record['profile']}, eval {record['eval_mode']}, helpers {adaptive['helpers']}",
    f"threshold {adaptive['threshold_mm']:.2f} mm ({adaptive['threshold_fraction']:.0%} of the "
    f"arm up to module {module}); stages of {adaptive['stage_s']:g} s, error = mean over "
    f"the last {adaptive['stage_s'] - adaptive['settle_s']:g} s",
    f"{'position error (mm)':<26}{'targets':>8}{'median':>9}{'IQR':>13}{'':>7}{'mean ± std':>15}",
  ]
  lines += [_row(entry["stage"], entry["error_mm"]) for entry in summary["stages"]]
  lines.append(_row("final (adaptive)", summary["final_error_mm"]))
  lines.append(_row("all modules on", summary["all_on_error_mm"]))
  lines.append(
    "modules that ended active: "
    + ", ".join(f"{modules} ({count})" for modules, count in summary["final_active"].items())
  )
  lines.append("effort saved against all modules on (%), sum of squared actions:")
  for key, name in (
    ("effort_saved_percent", "whole run"),
    ("holding_effort_saved_percent", "holding the target"),
  ):
    saved = summary[key]
    lines.append(
      f"  {name:<20} median {saved['median']:.1f}, IQR {saved['q25']:.1f} .. "
      f"{saved['q75']:.1f}, mean {saved['mean']:.1f} ± {saved['std']:.1f}"
    )
  lines.append(f"wall time {record['wall_time_s']:.1f} s")
  return "\n".join(lines)
