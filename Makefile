# Two commands do everything on a fresh machine: `make run` and `make test`.
# Both create the virtual environment in .venv and install what they need.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: run test bench models leaderboard

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -e '.[test]'
	touch $(STAMP)

run: $(STAMP)
	$(VENV)/bin/softbench run --task spiral --agent smpl

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q tests

bench: $(STAMP)
	$(VENV)/bin/python -m pytest -q benchmarks --benchmark-only --benchmark-columns=mean,stddev,rounds

models: $(STAMP)
	$(VENV)/bin/softbench models export --measure-speed

# Every agent on every task of the leaderboard's robots, then the Exp1S protocol, then the pages.
# PROFILE=paper (default) is the paper's budget: hours per agent on a laptop CPU. Every run reuses
# cached datasets, checkpoints and training snapshots, so an interrupted fill resumes; the pages
# show the newest record of each setting.
PROFILE ?= paper
LEADERBOARD_ROBOTS := tendon-3 pneumatic-433
LEADERBOARD_TASKS := babbling circle rectangle spiral reach
LEADERBOARD_AGENTS := smpl mlp lstm vae-lstm bilstm reference zero random
leaderboard: $(STAMP)
	set -e; for robot in $(LEADERBOARD_ROBOTS); do for task in $(LEADERBOARD_TASKS); do \
	  for agent in $(LEADERBOARD_AGENTS); do \
	    $(VENV)/bin/softbench run --robot $$robot --task $$task --agent $$agent --profile $(PROFILE); \
	  done; done; done
	$(VENV)/bin/softbench run --protocol exp1s --agent smpl --profile $(PROFILE)
	$(VENV)/bin/softbench leaderboard --write
