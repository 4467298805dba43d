"""The continual-learning figures of a stream's records, per seed (then mean ± std and bootstrap
intervals over seeds, as the leaderboard gives every figure).

E[s, c] is configuration c's end-effector error in physics after stage s (c <= s; NaN above the
diagonal), in mm or in % of the configuration's length.

- ``average_final``: the mean over configurations of the last row, E[S-1, c];
- ``forgetting``: per configuration c < S-1, the largest rise of its error after it was learned,
  max over s >= c of E[s, c] - E[c, c] (0 when it never rose); the mean over those
  configurations;
- ``forward_transfer``: per stage s >= 1 (the first has nothing to transfer from), the share of
  the reference's error (``independent``: a fresh network per configuration, same seed and
  budget) that the strategy removes on the configuration it just learned,
  (E_ref[s, s] - E[s, s]) / E_ref[s, s]; the mean over stages. Positive: the earlier stages
  helped; negative: they hurt;
- ``curve_transfer``: the same on the training curves (Continual World's forward transfer, on
  losses): 1 - AUC / AUC_ref, AUC the mean over the profile's epoch budget of the best validation
  loss so far (the last value held after early stopping).
"""

import numpy as np

from softbench import metrics as error_metrics

METRIC_FIELDS = {"mm": "position_mm", "%": "normalised_tip_percent"}


def error_matrix(seed_entry: dict, unit: str = "mm") -> np.ndarray:
  """E (stages, configurations) of one seed of a record, NaN above the diagonal."""
  field = METRIC_FIELDS[unit]
  stages = seed_entry["stages"]
  matrix = np.full((len(stages), len(stages)), np.nan)
  for stage, entry in enumerate(stages):
    for configuration, scores in enumerate(entry["scores"]):
      matrix[stage, configuration] = scores[field]
  return matrix


def matrices(record: dict, unit: str = "mm") -> np.ndarray:
  """E of every seed: (seeds, stages, configurations)."""
  return np.stack([error_matrix(entry, unit) for entry in record["per_seed"]])


def average_final(matrix: np.ndarray) -> float:
  return float(np.mean(matrix[-1]))


def forgetting_per_configuration(matrix: np.ndarray) -> np.ndarray:
  """Per configuration 0..S-2, the largest rise of its error after its own stage."""
  return np.array(
    [np.max(matrix[c:, c] - matrix[c, c]) for c in range(matrix.shape[0] - 1)], dtype=float
  )


def forgetting(matrix: np.ndarray) -> float:
  rises = forgetting_per_configuration(matrix)
  return float(np.mean(rises)) if rises.size else 0.0


def transfer_per_stage(matrix: np.ndarray, reference: np.ndarray) -> np.ndarray:
  """Per stage 1..S-1, (E_ref[s, s] - E[s, s]) / E_ref[s, s]."""
  own, theirs = np.diag(matrix)[1:], np.diag(reference)[1:]
  return (theirs - own) / theirs


def forward_transfer(matrix: np.ndarray, reference: np.ndarray) -> float:
  return float(np.mean(transfer_per_stage(matrix, reference)))


def curve_area(curve: list[float], max_epochs: int) -> float:
  """Mean over ``max_epochs`` of the best validation loss so far (the last held)."""
  if not curve:
    raise ValueError("a training curve needs at least one epoch")
  best = np.minimum.accumulate(np.asarray(curve, dtype=float))
  held = np.concatenate([best, np.full(max(0, max_epochs - best.size), best[-1])])
  return float(np.mean(held[:max_epochs]))


def curve_transfer(seed_entry: dict, reference_entry: dict, max_epochs: int) -> float | None:
  """The mean over stages 1..S-1 of 1 - AUC / AUC_ref of each stage's first training curve; None
  when the strategy did not train at those stages (``joint`` learns everything at the first)."""
  values = []
  for own, theirs in zip(seed_entry["stages"][1:], reference_entry["stages"][1:]):
    if not own["validation_curve"]:
      return None
    area = curve_area(own["validation_curve"][0], max_epochs)
    values.append(1.0 - area / curve_area(theirs["validation_curve"][0], max_epochs))
  return float(np.mean(values))


def summary(record: dict, unit: str = "mm") -> dict[str, error_metrics.Statistic]:
  """Mean and std over seeds of the average final error and of forgetting, in ``unit``."""
  per_seed = matrices(record, unit)
  return {
    "average_final": error_metrics.Statistic.of([average_final(m) for m in per_seed]),
    "forgetting": error_metrics.Statistic.of([forgetting(m) for m in per_seed]),
  }


def transfer(record: dict, reference: dict, unit: str = "mm") -> dict[str, list[float]]:
  """Per seed the seeds both records share: ``forward_transfer`` and ``curve_transfer`` of
  ``record`` against ``reference`` (``independent`` on the same stream, family and profile)."""
  theirs = {entry["seed"]: entry for entry in reference["per_seed"]}
  physics, curves = [], []
  max_epochs = record["profile_settings"]["max_epochs"]
  for entry in record["per_seed"]:
    if entry["seed"] not in theirs:
      continue
    other = theirs[entry["seed"]]
    physics.append(forward_transfer(error_matrix(entry, unit), error_matrix(other, unit)))
    curve = curve_transfer(entry, other, max_epochs)
    if curve is not None:
      curves.append(curve)
  return {"forward_transfer": physics, "curve_transfer": curves}
