# Two commands do everything on a fresh machine: `make run` and `make test`.
# Both create the virtual environment in .venv and install what they need: the current stack,
# physics v1 (MuJoCo 4, plugin-free rod; constraints.txt). The old stack, physics v0 (MuJoCo 3.17
# with the cable plugin, which MuJoCo 4 removed; constraints-v0.txt), goes in .venv-v0 for
# reproducing the records made on it: `make run-v0` (docs/physics-versions.md).
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed
VENV_V0 := .venv-v0
STAMP_V0 := $(VENV_V0)/.installed

.PHONY: install install-v0 install-gpu run run-v0 test smoke-v0 bench models leaderboard

# Python caches the bytecode of the modules it imports (a machine may switch that off with
# PYTHONDONTWRITEBYTECODE): pip need not compile all 16,000 files it installs (about 50 s, one
# core), when the runs and tests import about a fifth of them.
unexport PYTHONDONTWRITEBYTECODE

# One recipe for both stacks: `make VENV/.installed` with the constraints file beside it.
define install_stack
	$(PYTHON) -m venv $(1)
	$(1)/bin/pip install --quiet --upgrade pip
	$(1)/bin/pip install --quiet --no-compile -c $(2) -e '.[test]'
	touch $(1)/.installed
endef

$(STAMP): pyproject.toml constraints.txt
	$(call install_stack,$(VENV),constraints.txt)

$(STAMP_V0): pyproject.toml constraints-v0.txt
	$(call install_stack,$(VENV_V0),constraints-v0.txt)

install: $(STAMP)

install-v0: $(STAMP_V0)

# MuJoCo Warp (the gpu extra, 0.4 GB) for ArmBatch's warp backend; on the CPU it runs only the
# parity tests (tests/test_batch.py), on a GPU the vector environments (docs/compute.md).
install-gpu: $(STAMP)
	$(VENV)/bin/pip install --quiet --no-compile -c constraints.txt -e '.[test,gpu]'

run: $(STAMP)
	$(VENV)/bin/softbench run --task spiral --agent smpl

# The main job on the old stack (physics v0), whose committed records it re-scores from the zoo.
run-v0: $(STAMP_V0)
	$(VENV_V0)/bin/softbench run --task spiral --agent smpl

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q -n auto --dist worksteal tests

# CI's check of the old stack (physics v0): the rod against the cable plugin live, the versions'
# bookkeeping, and one robot, task and agent end to end (tests/test_old_stack.py).
smoke-v0: $(STAMP_V0)
	$(VENV_V0)/bin/python -m pytest -q -p no:cacheprovider tests/test_rod.py tests/test_versions.py \
	  tests/test_old_stack.py

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
