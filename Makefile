# Targets named in the README. Everything runs inside .venv, built from nothing by `make setup`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PROMPT ?= a tall, heavy man jogs forward and waves

.PHONY: setup test test-fast demo bench extension clean-venv

setup: $(VENV)/.installed

# torch is pinned first and alone: pip takes the CPU build of 2.13.0 from local disk.
$(VENV)/.installed: pyproject.toml setup.py
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q torch==2.13.0
	$(PY) -m pip install -q -e ".[dev]"
	touch $@

test: setup
	$(PY) -m pytest -q

test-fast: setup
	$(PY) -m pytest -q -m "not slow"

bench: setup
	$(PY) -m shapemove bench all --json out/bench.json

extension: setup
	$(PY) tools/build_extension.py --out dist

clean-venv:
	rm -rf $(VENV)
