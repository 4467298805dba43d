"""The zoo's physics-v0 agents scored again on physics v1, without retraining: what the change of
simulator alone does to each record the zoo stands behind.

The zoo's weights were trained on v0 (MuJoCo 3.17, cable plugin) and their cache keys name the v0
robots' hashes. On v1 this script keys every robot by the hash its zoo entries name
(``SoftArm.physics_sha256`` returns it), so that the cache finds those weights, and re-scores each
record's seeds in an empty data home (``zoo_verification.rescored``): the targets, the episodes and
the errors are simulated on v1. Prints one markdown row per record: the module-averaged position
error (mm) of the v0 record and of the v1 re-score (mean ± std over the seeds re-scored), and the
largest difference of a seed. A model the zoo lacks stops the script: a re-score never trains.

With ``--out FILE`` each row is also added to FILE (rewritten atomically) as soon as it is made,
and the records FILE already has a row of are skipped: an interrupted run, given the same FILE,
goes on with the records still to re-score (a paper-profile pass takes core-hours).

Usage (on the current stack, physics v1):
  python docs/analysis/rescore_on_v1.py [--agents smpl ...] [--profile default] [--seeds N]
      [--results leaderboard/results] [--zoo zoo] [--out rows.md]
"""

import argparse
from collections.abc import Callable
import pathlib
import re
import tempfile

import numpy as np

from softbench import records
from softbench import storage
from softbench import zoo
from softbench.records import fields as record_fields
from softbench.robots import base
from softbench.robots import versions
from softbench.runners import zoo_verification

CHECKOUT = pathlib.Path(__file__).resolve().parents[2]
METRIC = "position_mm"
HEADER = (
  f"| record (v0) | seeds | v0 {METRIC} | v1 re-score | largest seed difference (mm) |\n"
  "|---|---:|---|---|---:|\n"
)


def v0_hashes(entries) -> dict[str, str]:
  """The v0 hash of each robot, as the zoo's v0 entries name it (its v1 entries name another)."""
  hashes = {}
  for entry in entries:
    if entry.physics != versions.FIRST:
      continue
    config = entry.config
    names, shas = config.get("robots", [config.get("robot")]), config.get("robot_xml_sha256")
    for name, sha in zip(names, shas if isinstance(shas, list) else [shas]):
      if name is not None and sha is not None:
        hashes[name] = sha
  return hashes


def refusing_to_train(restore: Callable[[pathlib.Path], list[str]]):
  """``zoo.restore`` that stops the script where the zoo lacks a model: re-scoring must not train
  (a paper-profile model takes hours, and its scores would not be the record's weights')."""

  def restore_or_stop(cache_file: pathlib.Path) -> list[str]:
    taken = restore(cache_file)
    if not cache_file.is_file():
      raise SystemExit(f"error: the zoo has no {cache_file.name}; re-scoring would train it")
    return taken

  return restore_or_stop


def main(argv: list[str] | None = None) -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--agents", nargs="+", help="only these agents (default: all)")
  parser.add_argument("--profile", default="default")
  parser.add_argument("--seeds", type=int, default=None, help="seeds 0 .. N-1 (default: all)")
  parser.add_argument("--results", type=pathlib.Path, default=CHECKOUT / "leaderboard" / "results")
  parser.add_argument("--zoo", type=pathlib.Path, default=CHECKOUT / "zoo")
  parser.add_argument(
    "--out", type=pathlib.Path, help="also add each row to this file; skip its rows"
  )
  args = parser.parse_args(argv)
  if versions.current().name == versions.FIRST:
    raise SystemExit("error: run this on the current stack (physics v1), not the old one")
  entries = zoo.read_manifest(args.zoo).values()
  hashes = v0_hashes(entries)
  own_hash = base.SoftArm.physics_sha256
  base.SoftArm.physics_sha256 = lambda arm: hashes.get(arm.name) or own_hash(arm)
  zoo.restore = refusing_to_train(zoo.restore)
  found = {path.name: record for path, record in records.read_folder(args.results)}
  wanted = {}
  for name, seed in zoo_verification.planned(args.zoo, tuple(args.agents or ()), False):
    record = found.get(name)
    if record is None or record_fields.physics_of(record) != versions.FIRST:
      continue
    if record["profile"] == args.profile and (args.seeds is None or seed < args.seeds):
      wanted.setdefault(name, []).append(seed)
  table = args.out.read_text(encoding="utf-8") if args.out and args.out.exists() else HEADER
  done = set(re.findall(r"^\| (\S+\.json) \|", table, re.MULTILINE))
  print(HEADER, end="")
  with tempfile.TemporaryDirectory(prefix="softbench-rescore-references-") as shared:
    references = pathlib.Path(shared)  # Targets simulated once, from the physics alone.
    for name in sorted(wanted):
      if name in done:
        continue
      record, seeds = found[name], sorted(wanted[name])
      old, new = [], []
      for seed in seeds:
        stored = next(entry for entry in record["per_seed"] if entry["seed"] == seed)
        with zoo_verification.empty_data_home(references):
          again = zoo_verification.rescored(record, seed)
        old.append(_mean(stored))
        new.append(_mean(again))
      worst = float(np.max(np.abs(np.subtract(new, old))))
      row = (
        f"| {name} | {len(seeds)} | {np.mean(old):.4f} ± {np.std(old):.4f} | "
        f"{np.mean(new):.4f} ± {np.std(new):.4f} | {worst:.2e} |\n"
      )
      print(row, end="", flush=True)
      if args.out:
        table += row
        storage.write_atomically(args.out, table)


def _mean(entry: dict) -> float:
  """A seed's module-averaged position error (mm); of an Exp1S seed, the mean closed-loop one."""
  if METRIC in entry:
    return entry[METRIC]["mean"]
  scores = [s[METRIC] for task in entry["scores"]["closed"].values() for s in task]
  return float(np.mean(scores))


if __name__ == "__main__":
  main()
