# recipdyn: one command each for run, test and benchmark on a fresh machine.
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
OUT ?= out

.PHONY: env warmup run test test-all test-fast bench lint format docs clean diagnoser

$(STAMP): pyproject.toml requirements/constraints.txt
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "need $(PYTHON) on PATH (set PYTHON=...)"; exit 2; }
	$(PYTHON) -m venv $(VENV)
	@echo "installing recipdyn and its dependencies into $(VENV) with pip (quiet; a few minutes on a fresh machine)..."
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c requirements/constraints.txt -e ".[dev]"
	@touch $(STAMP)

env: $(STAMP)

# compile the paper's model once, before reproduce's worker processes need it (each would
# otherwise compile it on its own); later runs load it from the cache in about a second
warmup: $(STAMP)
	$(VENV)/bin/recipdyn warmup compressor

run: warmup
	$(VENV)/bin/recipdyn reproduce --out $(OUT)

# the suite in parallel: one worker per logical CPU, at most 4 (each holds ~1 GB), a test file
# on one worker (its module fixtures, a shared run or sweep store, are computed once; the
# per-model checks of test_models.py go out by model: tests/conftest.py);
# TEST_JOBS=0 runs it in this process, TEST_JOBS=N on N workers
TEST_JOBS ?= logical
test: $(STAMP)
	$(PY) -m pytest -q --timeout=1200 -n $(TEST_JOBS) --maxprocesses=4 --dist loadfile \
		--durations=25 -m "not exhaustive"

# the whole component matrix too (every combination runs, not only every pair: ~15 min more)
test-all: $(STAMP)
	$(PY) -m pytest -q --timeout=1200 -n $(TEST_JOBS) --maxprocesses=4 --dist loadfile \
		--durations=25

test-fast: $(STAMP)
	$(PY) -m pytest -q -m "not slow" -x

bench: $(STAMP)
	$(PY) -m pip install --quiet -c requirements/constraints.txt -e ".[bench]"
	$(PY) benchmarks/run_all.py

docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict -d site

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks examples
	$(VENV)/bin/ruff format --check src tests benchmarks examples

format: $(STAMP)
	$(VENV)/bin/ruff format src tests benchmarks
	$(VENV)/bin/ruff check --fix src tests benchmarks

clean:
	rm -rf $(VENV) $(OUT) site .pytest_cache

# the diagnoser shipped with recipdyn (docs/diagnosis.md): the default data set (40 operating
# conditions x 9 classes x 4 records, severities drawn in [0.25, 1], accelerometer SNRs drawn
# in [10, 40] dB, each record's measurement chain drawn from recipdyn.chain's ranges: 1440
# records, ~30 min on 2 loaded cores), trained, evaluated
diagnoser: warmup
	$(VENV)/bin/recipdyn dataset -o $(OUT)/diagnoser-data --conditions 40 --severity-range 0.25,1 --draws 4 --snr-range 10,40 --resume
	$(VENV)/bin/recipdyn train $(OUT)/diagnoser-data -o src/recipdyn/diagnosis/data/default.skops --report $(OUT)/diagnoser-report
