"""Wall time of a leaderboard grid: one `softbench sweep` against the loop that it replaced.

The loop is `make leaderboard`'s before the sweep (8ecea43): one `softbench run` per setting,
robot > task > agent, skipping a setting that has a record.

The grid is measured in parts (PARTS: sets of agents, each over every task and seed), so that
each way of each part fits in one session of a machine that may not outlive it. The babbling
dataset, which every learned agent needs, is collected once (`--way dataset`, timed) and copied
into each way's data home before it starts, so it is counted once, not once a part. Each way of
a part runs from that data home, of its own, with the zoo off, under WORK/PART/WAY/ (`home/`,
`results/`). Both resume on the same machine: stopped (Ctrl-C, SIGTERM) and started again, a way
goes on where it was; every stretch of wall time it ran, whole or cut short, is appended to
WORK/PART/WAY/times.jsonl (what an interruption loses is paid again, and counted). A way that
ends writes WORK/PART/WAY/finished.json (its total, and a digest of every record's scores):
commit those files, with the times, and `--report` adds them up on any machine.

A part's sweep loses, against one sweep of the whole grid, the cores left idle at the part's
end, and pays its Ray start again, so the parts' sum is an upper bound on the whole sweep.

Usage:
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --way dataset
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --part learners --way loop
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --part learners --way sweep
  python docs/analysis/sweep_vs_loop.py --work docs/analysis/sweep_vs_loop --report
(defaults: tendon-3, the leaderboard's tasks, the default profile, 5 seeds)
"""

import argparse
import datetime
import hashlib
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

from softbench import profiles
from softbench import records
from softbench import storage
from softbench import zoo
from softbench.data import dataset as babbling_dataset
from softbench.leaderboard import grid
from softbench.learning import inverse as inverse_training

WAYS = ("loop", "sweep")
PARTS = {  # The grid: the eight agents of its time (the reference came later).
  "learners": ("smpl", "mlp", "lstm", "vae-lstm"),
  "bilstm": ("bilstm",),
  "sac": ("sac",),
  "baselines": ("zero", "random"),
}
DATASET = "dataset"  # The folder of the babbling dataset's collection, beside the parts'.
GRACE_S = 300.0  # (s) How long an interrupted command has to save its state before it is killed.


def _command(*arguments: str) -> list[str]:
  return [sys.executable, "-m", "softbench.launcher", *arguments]


def _has_record(results: pathlib.Path, agent: str, robot: str, task: str, profile: str) -> bool:
  return any(results.glob(f"{agent}-{robot}-{task}-{profile}-physics-*.json"))


def _timed(command: list[str], folder: pathlib.Path, what: str) -> int:
  """Runs ``command`` with the way's data home and the zoo off; appends its wall time to
  ``folder/times.jsonl``, interrupted or not. An interruption is passed on to the command (its
  own session: Ctrl-C reaches it once, from here) and raised again once it has ended."""
  environment = {
    **os.environ,
    storage.HOME_VARIABLE: str(folder / "home"),
    zoo.VARIABLE: zoo.OFF,
  }
  started, interrupted = time.perf_counter(), False
  process = subprocess.Popen(command, env=environment, start_new_session=True)
  try:
    returncode = process.wait()
  except KeyboardInterrupt:
    interrupted = True
    process.send_signal(signal.SIGINT)
    try:
      returncode = process.wait(GRACE_S)
    except subprocess.TimeoutExpired:
      process.kill()
      returncode = process.wait()
  stretch = {
    "what": what,
    "seconds": round(time.perf_counter() - started, 3),
    "returncode": returncode,
    "interrupted": interrupted,
    "ended": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
  }
  with open(folder / "times.jsonl", "a") as times:
    times.write(json.dumps(stretch) + "\n")
    times.flush()
    os.fsync(times.fileno())
  if interrupted:
    raise KeyboardInterrupt
  return returncode


def _dataset_folder(args: argparse.Namespace, home: pathlib.Path) -> pathlib.Path:
  config = babbling_dataset.generating_config(
    args.robot, profiles.get(args.profile).samples, inverse_training.DATA_SEED
  )
  return babbling_dataset.dataset_folder(config, home)


def collect_dataset(args: argparse.Namespace) -> None:
  """Collects the runs' babbling dataset once, timed as a way of its own."""
  folder = args.work / DATASET
  folder.mkdir(parents=True, exist_ok=True)
  samples = str(profiles.get(args.profile).samples)
  command = _command(
    "collect",
    "--robot",
    args.robot,
    "--samples",
    samples,
    "--seed",
    str(inverse_training.DATA_SEED),
  )
  if _timed(command, folder, "collect"):
    raise SystemExit("the collection failed; see its output above")
  _finish(folder, {})


def _seed_home(args: argparse.Namespace, folder: pathlib.Path) -> None:
  """Copies the collected dataset into the way's data home (before its first stretch)."""
  source = _dataset_folder(args, args.work / DATASET / "home")
  target = _dataset_folder(args, folder / "home")
  if target.exists():
    return
  if not (args.work / DATASET / "finished.json").exists():
    raise SystemExit(f"collect the dataset first: --work {args.work} --way {DATASET}")
  partial = target.with_name(target.name + ".copying")
  shutil.rmtree(partial, ignore_errors=True)  # A copy cut short by a stop.
  partial.parent.mkdir(parents=True, exist_ok=True)
  shutil.copytree(source, partial)
  os.replace(partial, target)


def _per_seed(results: pathlib.Path) -> dict[str, list[dict]]:
  """Each record's scores seed for seed, by AGENT-ROBOT-TASK."""
  return {
    "-".join(record[key] for key in ("agent", "robot", "task")): record["per_seed"]
    for _, record in records.read_folder(results)
  }


def scores(per_seed: list[dict]) -> dict:
  """A record's scores in brief: the sha256 of all of them, seed for seed (what two ways compare),
  and each seed's mean position error (mm), to read."""
  canonical = json.dumps(per_seed, sort_keys=True).encode()
  return {
    "sha256": hashlib.sha256(canonical).hexdigest(),
    "position_mm": [seed["position_mm"]["mean"] for seed in per_seed],
  }


def _finish(folder: pathlib.Path, digests: dict) -> None:
  """Writes the way's total and its records' ``digests`` to ``folder/finished.json``."""
  stretches = [json.loads(line) for line in (folder / "times.jsonl").read_text().splitlines()]
  summary = {
    "seconds": round(sum(stretch["seconds"] for stretch in stretches), 3),
    "stretches": len(stretches),
    "interrupted": sum(stretch["interrupted"] for stretch in stretches),
    "ended": stretches[-1]["ended"],
    "scores": digests,
  }
  storage.write_atomically(folder / "finished.json", json.dumps(summary, indent=1) + "\n")


def run_way(args: argparse.Namespace) -> None:
  folder = args.work / args.part / args.way
  results = folder / "results"
  results.mkdir(parents=True, exist_ok=True)
  _seed_home(args, folder)
  agents = PARTS[args.part]
  shared = ["--profile", args.profile, "--seeds", str(args.seeds), "--results", str(results)]
  if args.way == "sweep":
    command = _command(
      "sweep", "--robots", args.robot, "--tasks", *args.tasks, "--agents", *agents, *shared
    )
    if _timed(command, folder, "sweep"):
      raise SystemExit("the sweep failed; see its output above")
  else:
    for task in args.tasks:
      for agent in agents:
        if _has_record(results, agent, args.robot, task, args.profile):
          continue
        command = _command("run", "--robot", args.robot, "--task", task, "--agent", agent, *shared)
        if _timed(command, folder, f"{agent}-{args.robot}-{task}"):
          raise SystemExit(f"softbench run failed on {agent}-{args.robot}-{task}; see above")
  _finish(folder, {name: scores(per_seed) for name, per_seed in _per_seed(results).items()})


def _finished(folder: pathlib.Path) -> dict | None:
  path = folder / "finished.json"
  return json.loads(path.read_text()) if path.exists() else None


def report(work: pathlib.Path) -> None:
  """Each finished part's two wall times, their sums with the dataset's collection, and whether
  the two ways' records agree seed for seed."""
  dataset = _finished(work / DATASET)
  print(f"dataset: {dataset['seconds']:.1f} s" if dataset else "dataset: not collected")
  totals, both, same = {way: 0.0 for way in WAYS}, 0, 0
  for part, agents in PARTS.items():
    ways = {way: _finished(work / part / way) for way in WAYS}
    print(
      f"{part} ({' '.join(agents)}): "
      + ", ".join(
        f"{way} {ways[way]['seconds']:.1f} s in {ways[way]['stretches']} stretches"
        f" ({ways[way]['interrupted']} interrupted)"
        if ways[way]
        else f"{way} not finished"
        for way in WAYS
      )
    )
    if not all(ways.values()):
      continue
    for way in WAYS:
      totals[way] += ways[way]["seconds"]
    print(f"  the sweep took {ways['sweep']['seconds'] / ways['loop']['seconds']:.2f} of the loop")
    loop, sweep = ways["loop"]["scores"], ways["sweep"]["scores"]
    names = sorted(set(loop) & set(sweep))
    differ = [name for name in names if loop[name]["sha256"] != sweep[name]["sha256"]]
    both, same = both + len(names), same + len(names) - len(differ)
    for name in differ:
      print(f"  scores differ: {name}")
  collect = dataset["seconds"] if dataset else 0.0
  print(
    ", ".join(f"{way}: {totals[way] + collect:.1f} s" for way in WAYS)
    + " (the finished parts and the dataset's collection)"
  )
  print(f"records of both ways: {both}, with the same scores seed for seed: {same}")


def main() -> None:
  axes = grid.lists()
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--work", type=pathlib.Path, required=True, help="the measurement's folder")
  parser.add_argument("--way", choices=(DATASET, *WAYS), help="run (or resume) this way")
  parser.add_argument("--part", choices=PARTS, help="the part of the grid (for loop and sweep)")
  parser.add_argument("--report", action="store_true", help="print the finished parts' figures")
  parser.add_argument("--robot", default="tendon-3")
  parser.add_argument("--tasks", nargs="+", default=list(axes["tasks"]))
  parser.add_argument("--profile", default=profiles.DEFAULT_PROFILE)
  parser.add_argument("--seeds", type=int, default=profiles.get(profiles.DEFAULT_PROFILE).seeds)
  args = parser.parse_args()
  if (args.way is None) == (not args.report):
    parser.error("give either --way or --report")
  if args.way in WAYS and args.part is None:
    parser.error(f"--way {args.way} needs --part")
  if args.way is not None:
    try:
      collect_dataset(args) if args.way == DATASET else run_way(args)
    except KeyboardInterrupt:
      raise SystemExit(f"interrupted; run the same command again to resume the {args.way}")
  else:
    report(args.work)


if __name__ == "__main__":
  signal.signal(signal.SIGTERM, signal.default_int_handler)  # `kill` stops it as Ctrl-C does.
  # Started in the background of a script (nohup ... &), a process ignores SIGINT, and so would
  # the runs it starts, which then finished a setting rather than stop when interrupted; a
  # handler of its own makes their SIGINT the default again.
  signal.signal(signal.SIGINT, signal.default_int_handler)
  main()
