# Two commands do everything on a fresh machine: `make run` and `make test`.
# Both create the virtual environment in .venv and install what they need.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: run test bench models leaderboard

# Python caches the bytecode of the modules it imports (a machine may switch that off with
# PYTHONDONTWRITEBYTECODE): pip need not compile all 16,000 files it installs (about 50 s, one
# core), when the runs and tests import about a fifth of them.
unexport PYTHONDONTWRITEBYTECODE

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet --no-compile -c constraints.txt -e '.[test]'
	touch $(STAMP)

run: $(STAMP)
	$(VENV)/bin/softbench run --task spiral --agent smpl

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q -n auto --dist worksteal tests

bench: $(STAMP)
	$(VENV)/bin/python -m pytest -q benchmarks --benchmark-only --benchmark-columns=mean,stddev,rounds

models: $(STAMP)
	$(VENV)/bin/softbench models export --measure-speed

# Every agent on every task of the leaderboard's robots, and Exp1S on each tendon family, as one
# sweep on Ray (softbench sweep; each dataset, forward model, agent and Exp1S network built once),
# then the pages. PROFILE=paper (default) is the paper's budget: hours per agent on a laptop CPU.
# A setting that already has a record of this profile in leaderboard/results is skipped, and work
# under way resumes from the cached datasets, checkpoints, training snapshots and finished seeds,
# so an interrupted fill goes on where it stopped; the pages show the newest record of each
# setting. ADDRESS=HOST:PORT runs the sweep on that Ray cluster (docs/sweep.md).
PROFILE ?= paper
ADDRESS ?=
RESULTS := leaderboard/results
# The grid comes from the library (softbench.leaderboard.grid), once softbench is installed.
LEADERBOARD_ROBOTS = $(shell $(VENV)/bin/softbench leaderboard --grid robots)
LEADERBOARD_TASKS = $(shell $(VENV)/bin/softbench leaderboard --grid tasks)
LEADERBOARD_AGENTS = $(shell $(VENV)/bin/softbench leaderboard --grid agents)
EXP1S_FAMILIES = $(shell $(VENV)/bin/softbench leaderboard --grid families)
leaderboard: $(STAMP)
	$(VENV)/bin/softbench sweep --robots $(LEADERBOARD_ROBOTS) --tasks $(LEADERBOARD_TASKS) \
	  --agents $(LEADERBOARD_AGENTS) --protocol exp1s --families $(EXP1S_FAMILIES) \
	  --profile $(PROFILE) $(if $(ADDRESS),--address $(ADDRESS)) --results $(RESULTS)
	$(VENV)/bin/softbench leaderboard --results $(RESULTS) --write
