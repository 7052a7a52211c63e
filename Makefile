# The two commands of the README. Each creates its own environment in .venv if it is missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

## Run the main job on every bundled example (writes out/).
demo: $(STAMP)
	$(BIN)/screwkit demo examples --output-dir out

## Lint, type-check and run the whole test suite.
test: $(STAMP)
	$(BIN)/ruff check src tests validation benchmarks
	$(BIN)/mypy
	$(BIN)/python -m pytest

## Benchmarks (not tests): prints a table.
bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[dev,bench]"
	$(BIN)/python benchmarks/run.py
