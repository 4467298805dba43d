"""Wall time of a leaderboard grid: one `softbench sweep` against the loop that it replaced.

The loop is `make leaderboard`'s before the sweep (8ecea43): one `softbench run` per setting,
robot > task > agent, skipping a setting that has a record. Each way runs from an empty data home
of its own with the zoo off, under WORK/WAY/ (`home/`, `results/`). Both resume: stopped (Ctrl-C,
SIGTERM) and started again, a way goes on where it was. Every stretch of wall time it ran, whole
or cut short, is appended to WORK/WAY/times.jsonl, so a total adds up across restarts and
sessions (what an interruption loses is paid again, and counted).

Usage:
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --way loop
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --way sweep
  python docs/analysis/sweep_vs_loop.py --work /work/runs/grid --report
(defaults: tendon-3, the leaderboard's tasks and agents, the default profile, 5 seeds)
"""

import argparse
import datetime
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

from softbench import profiles
from softbench import records
from softbench import storage
from softbench import zoo
from softbench.leaderboard import grid

WAYS = ("loop", "sweep")
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


def run_way(args: argparse.Namespace) -> None:
  folder = args.work / args.way
  results = folder / "results"
  results.mkdir(parents=True, exist_ok=True)
  shared = ["--profile", args.profile, "--seeds", str(args.seeds), "--results", str(results)]
  if args.way == "sweep":
    command = _command(
      "sweep", "--robots", *args.robots, "--tasks", *args.tasks, "--agents", *args.agents, *shared
    )
    if _timed(command, folder, "sweep"):
      raise SystemExit("the sweep failed; see its output above")
    return
  for robot in args.robots:
    for task in args.tasks:
      for agent in args.agents:
        if _has_record(results, agent, robot, task, args.profile):
          continue
        command = _command("run", "--robot", robot, "--task", task, "--agent", agent, *shared)
        if _timed(command, folder, f"{agent}-{robot}-{task}"):
          raise SystemExit(f"softbench run failed on {agent}-{robot}-{task}; see above")


def report(work: pathlib.Path) -> None:
  """Each way's wall time (its stretches added up) and whether the two ways' records agree."""
  written = {}
  for way in WAYS:
    path = work / way / "times.jsonl"
    stretches = (
      [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []
    )
    cut = sum(stretch["interrupted"] for stretch in stretches)
    total = sum(stretch["seconds"] for stretch in stretches)
    written[way] = (
      {
        "-".join(record[key] for key in ("agent", "robot", "task")): record
        for _, record in records.read_folder(work / way / "results")
      }
      if (work / way / "results").is_dir()
      else {}
    )
    line = f"{way}: {total:.1f} s in {len(stretches)} stretches ({cut} interrupted); "
    line += f"{len(written[way])} records"
    if way == "loop":  # A run's record times its work, not its process starting and importing.
      line += f", {sum(record['wall_time_s'] for record in written[way].values()):.1f} s of runs"
    print(line)
  both = sorted(set(written["loop"]) & set(written["sweep"]))
  same = [
    name for name in both if written["loop"][name]["per_seed"] == written["sweep"][name]["per_seed"]
  ]
  print(f"records of both ways: {len(both)}, with the same scores seed for seed: {len(same)}")
  for name in sorted(set(both) - set(same)):
    print(f"  scores differ: {name}")


def main() -> None:
  axes = grid.lists()
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--work", type=pathlib.Path, required=True, help="the measurement's folder")
  parser.add_argument("--way", choices=WAYS, help="run (or resume) this way")
  parser.add_argument("--report", action="store_true", help="print both ways' figures so far")
  parser.add_argument("--robots", nargs="+", default=["tendon-3"])
  parser.add_argument("--tasks", nargs="+", default=list(axes["tasks"]))
  parser.add_argument("--agents", nargs="+", default=list(axes["agents"]))
  parser.add_argument("--profile", default=profiles.DEFAULT_PROFILE)
  parser.add_argument("--seeds", type=int, default=profiles.get(profiles.DEFAULT_PROFILE).seeds)
  args = parser.parse_args()
  if (args.way is None) == (not args.report):
    parser.error("give either --way or --report")
  if args.way is not None:
    try:
      run_way(args)
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
