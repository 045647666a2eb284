# Two commands do all the set-up on a fresh clone (Python 3.11 + make):
#   make repro   - create .venv if missing, install, run the main jobs (the MSE table, full state and with sensors)
#   make test    - same set-up with test extras, the lint and type gate (make lint), then the whole test suite
#   make docs    - same set-up with the docs extras, build the HTML site (docs/_build/html)
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
TSTAMP := $(VENV)/.installed-test
DSTAMP := $(VENV)/.installed-docs

.PHONY: repro lint test bench docs clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e ".[slycot]"
	touch $@

$(TSTAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e ".[test,slycot]"
	touch $@ $(STAMP)

$(DSTAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e ".[docs]"
	touch $@ $(STAMP)

repro: $(STAMP)
	$(PY) paper_repro/mse_table.py --out out
	$(PY) paper_repro/mse_table_sensors.py --out out

# The gate: ruff (rules in pyproject.toml) and mypy (cache in .venv): ~11 s with a cold cache, ~1 s warm.
lint: $(TSTAMP)
	$(PY) -m ruff check
	$(PY) -m mypy

# Small matrices: threaded BLAS only oversubscribes the 2 cores, so pin it.
test: lint
	OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 $(PY) -m pytest

bench: $(STAMP)
	for f in benchmarks/bench_*.py; do $(PY) -m benchmarks.$$(basename $$f .py) || exit 1; done

# Warnings are errors, cross-references nitpicky; the examples run on the way (docs/examples).
docs: $(DSTAMP)
	OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 \
		$(PY) -m sphinx -b html -W --keep-going -n -q docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

clean:
	rm -rf $(VENV) out .pytest_cache docs/_build docs/api docs/auto_examples docs/_generated docs/validation/results docs/sg_execution_times.rst
