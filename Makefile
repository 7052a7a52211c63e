# The two commands of the README. Each creates its own environment in .venv if it is missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench viewer

# The browser tests (tests/report) drive Debian's chromium; install it when it is missing.
CHROMIUM := /usr/bin/chromium
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

$(CHROMIUM):
	$(SUDO) apt-get update -q
	DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q chromium

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev,crosscheck]"
	touch $(STAMP)

VALIDATION := bagci1969/analysis_tables bagci1969/synthesis rahman1996/kinematics rahman1996/dynamics rahman1996/balancing

## One small design sweep (its heat map goes into out/index.html), the main job on every bundled
## example, and both seed systems' reports (writes out/).
demo: $(STAMP)
	mkdir -p out
	$(BIN)/screwkit sweep examples/rsrc_fig7_dynamics.toml --vary d2=4:5:9 --vary e=0.5:1.5:5 \
		--job dynamics --output out/sweep_rsrc_dynamics.parquet --plot out/sweep_rsrc_dynamics.png --fresh
	$(BIN)/screwkit demo examples --output-dir out
	mkdir -p out/validation
	@for v in $(VALIDATION); do \
		echo "validation/$$v.py -> out/validation/$$(echo $$v | tr / _).md"; \
		$(BIN)/python validation/$$v.py > out/validation/$$(echo $$v | tr / _).md || exit 1; \
	done

## Lint, type-check and run the whole test suite (installs Debian's chromium if missing).
## The suite runs on two processes (pytest-xdist); one BLAS/OpenMP thread each, so the two
## do not oversubscribe the cores. A targeted `python -m pytest tests/...` stays serial.
test: $(STAMP) $(CHROMIUM)
	$(BIN)/ruff check src tests validation benchmarks
	$(BIN)/mypy
	OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 $(BIN)/python -m pytest -n 2

## Benchmarks (not tests): prints a table.
bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[dev,bench]"
	$(BIN)/python benchmarks/run.py

## Rebuild the report viewer bundle (three.js + Chart.js) from viewer/ with npm; the built
## file is committed, so only front-end changes need this.
viewer:
	cd viewer && npm ci --no-audit --no-fund && npm run build
