"""What ``softbench tune`` prints of a study's summary (``study.summary``)."""

from softbench.agents import hyperparameters


def summary_text(study_summary: dict) -> str:
  """The trials' tally, the previous and the best values' validation MSE, the best values and,
  once confirmed, both at the profile's full epoch budget; one fact a line."""
  trials, previous = study_summary["trials"], study_summary["previous_values"]
  best = study_summary["best"]
  loss = hyperparameters.loss_text
  lines = [
    f"{study_summary['agent']} on {study_summary['robot']}, profile {study_summary['profile']}: "
    f"{trials['complete']} complete, {trials['pruned']} pruned, {trials['fail']} failed"
  ]
  if previous is not None:
    lines.append(
      f"previous values (trial {previous['trial']}): validation MSE {loss(previous['value'])}"
    )
  if best is not None:
    lines.append(f"best trial {best['trial']}: validation MSE {loss(best['value'])}")
    lines += [f"  {name} = {value:g}" for name, value in best["params"].items()]
  if "full_budget" in study_summary:
    check = study_summary["full_budget"]
    lines.append(
      f"at the profile's {check['epochs']} epochs: previous values {loss(check['previous'])}, "
      f"best {loss(check['best'])}"
    )
  return "\n".join(lines)
