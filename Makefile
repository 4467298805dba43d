# Two commands do everything on a fresh machine: `make run` and `make test`.
# Both create the virtual environment in .venv and install what they need.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: run test bench models

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
