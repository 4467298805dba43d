# Two commands do everything on a fresh machine: `make run` and `make test`.
# Both create the virtual environment in .venv and install what they need.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: run test bench models leaderboard

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -c constraints.txt -e '.[test]'
	touch $(STAMP)

run: $(STAMP)
	$(VENV)/bin/softbench run --task spiral --agent smpl

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q -n auto --dist worksteal tests

bench: $(STAMP)
	$(VENV)/bin/python -m pytest -q benchmarks --benchmark-only --benchmark-columns=mean,stddev,rounds

models: $(STAMP)
	$(VENV)/bin/softbench models export --measure-speed

# Every agent on every task of the leaderboard's robots as one sweep on Ray (softbench sweep; each
# dataset, forward model and agent built once), then Exp1S on each tendon family, then the pages.
# PROFILE=paper (default) is the paper's budget: hours per agent on a laptop CPU. A setting that
# already has a record of this profile in leaderboard/results is skipped, and work under way
# resumes from the cached datasets, checkpoints, training snapshots and finished seeds, so an
# interrupted fill goes on where it stopped; the pages show the newest record of each setting.
# ADDRESS=HOST:PORT runs the sweep on that Ray cluster (docs/sweep.md); WORKERS=N: processes per
# Exp1S run (softbench run --workers; empty: one per core).
PROFILE ?= paper
ADDRESS ?=
WORKERS ?=
RESULTS := leaderboard/results
# The grid comes from the library (softbench.leaderboard.grid), once softbench is installed.
LEADERBOARD_ROBOTS = $(shell $(VENV)/bin/softbench leaderboard --grid robots)
LEADERBOARD_TASKS = $(shell $(VENV)/bin/softbench leaderboard --grid tasks)
LEADERBOARD_AGENTS = $(shell $(VENV)/bin/softbench leaderboard --grid agents)
EXP1S_FAMILIES = $(shell $(VENV)/bin/softbench leaderboard --grid families)
leaderboard: $(STAMP)
	$(VENV)/bin/softbench sweep --robots $(LEADERBOARD_ROBOTS) --tasks $(LEADERBOARD_TASKS) \
	  --agents $(LEADERBOARD_AGENTS) --profile $(PROFILE) $(if $(ADDRESS),--address $(ADDRESS)) \
	  --results $(RESULTS)
	set -e; for family in $(EXP1S_FAMILIES); do \
	  named=$$([ $$family = tendon ] || echo "$$family-"); \
	  if ls $(RESULTS)/smpl-exp1s-$${named}$(PROFILE)-*.json >/dev/null 2>&1; then \
	    echo "skipped exp1s on $$family: it has a $(PROFILE) record"; continue; fi; \
	  $(VENV)/bin/softbench run --protocol exp1s --family $$family --agent smpl \
	    --profile $(PROFILE) $(if $(WORKERS),--workers $(WORKERS)) --results $(RESULTS); \
	done
	$(VENV)/bin/softbench leaderboard --results $(RESULTS) --write
