"""Simulation speed of both physics versions in one run: physics v0 (MuJoCo 3.17, cable plugin,
the old stack in .venv-v0) and v1 (MuJoCo 4, plugin-free rod, .venv), alternating.

Each measurement is ``softbench.robots.measure.simulation_speed`` (MuJoCo's rollout on one thread,
5 s of random actuation) in a fresh process of the stack's interpreter; the stacks take turns,
``--rounds`` times per robot, and the best of the rounds is kept (the least disturbed). Prints a
markdown table: steps per second and times real time on each stack, and their ratio.

Usage:
  python docs/analysis/stack_speed.py [--robots tendon-3 ...] [--rounds 3]
      [--v0 .venv-v0/bin/python] [--v1 .venv/bin/python]
"""

import argparse
import json
import pathlib
import subprocess

CHECKOUT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_ROBOTS = ("tendon-1", "tendon-3", "tendon-5", "tendon-local-3", "tendon-local-5")
_MEASURE = (
  "import json, sys; from softbench import robots; from softbench.robots import measure, versions;"
  "arm = robots.make(sys.argv[1]); speed = measure.simulation_speed(arm);"
  "print(json.dumps({**speed, 'physics': versions.current().name,"
  " 'mujoco': versions.engine_version(), 'backbone': versions.current().backbone}))"
)


def measure(python: str, robot: str) -> dict:
  """One measurement of ``robot`` in a fresh process of ``python``."""
  result = subprocess.run(
    [python, "-c", _MEASURE, robot], capture_output=True, text=True, check=True, cwd=CHECKOUT
  )
  return json.loads(result.stdout)


def best_of(python_by_stack: dict[str, str], robot: str, rounds: int) -> dict[str, dict]:
  """The fastest of ``rounds`` alternating measurements of ``robot`` on each stack."""
  best = {}
  for _ in range(rounds):
    for stack, python in python_by_stack.items():
      found = measure(python, robot)
      if stack not in best or found["steps_per_second"] > best[stack]["steps_per_second"]:
        best[stack] = found
  return best


def main(argv: list[str] | None = None) -> None:
  parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
  parser.add_argument("--robots", nargs="+", default=list(DEFAULT_ROBOTS))
  parser.add_argument("--rounds", type=int, default=3)
  parser.add_argument("--v0", default=str(CHECKOUT / ".venv-v0" / "bin" / "python"))
  parser.add_argument("--v1", default=str(CHECKOUT / ".venv" / "bin" / "python"))
  args = parser.parse_args(argv)
  stacks = {"v0": args.v0, "v1": args.v1}
  print("| robot | v0 steps/s (x real time) | v1 steps/s (x real time) | v1 / v0 |")
  print("|---|---|---|---|")
  for robot in args.robots:
    best = best_of(stacks, robot, args.rounds)
    cells = [
      f"{best[s]['steps_per_second']:,.0f} ({best[s]['real_time_factor']:.1f})" for s in stacks
    ]
    ratio = best["v1"]["steps_per_second"] / best["v0"]["steps_per_second"]
    print(f"| {robot} | {cells[0]} | {cells[1]} | {ratio:.2f} |", flush=True)
  seen = {
    s: f"physics {best[s]['physics']}, MuJoCo {best[s]['mujoco']}, tendon arms' backbone "
    f"{best[s]['backbone']}"
    for s in stacks
  }
  print(f"\nv0: {seen['v0']}; v1: {seen['v1']}")


if __name__ == "__main__":
  main()
