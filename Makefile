# Two entry points: `make run` (set up, run the example) and `make test` (set up, run the tests).
PY := .venv/bin/python
export NUMBA_CACHE_DIR := $(CURDIR)/.numba_cache
export OMP_NUM_THREADS := 1
export NUMBA_NUM_THREADS := 1
export OPENBLAS_NUM_THREADS := 1

.PHONY: setup run test test-all mutations loaded

setup:
	bash scripts/setup.sh

run: setup
	$(PY) -m ensemble run examples/small.toml -o small.h5 --force

test: setup
	$(PY) -m pytest -q -m "not slow"

test-all: setup
	$(PY) -m pytest -q

# plausible bugs applied one at a time to a copy of the repository; every one must be caught (tests/mutations.py)
mutations: setup
	$(PY) tests/mutations.py

# the suite five times in a row beside two CPU-bound processes: no test may hang or flake under load
loaded: setup
	bash tests/loaded.sh 5 2
