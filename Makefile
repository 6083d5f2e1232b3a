# Two entry points: `make run` (set up, run the example) and `make test` (set up, run the tests).
# STACK (scripts/setup.sh): auto (default: the machine's MPI and parallel HDF5 when found, else
# wheels), parallel or wheels. `make test` tests the parallel writer, so it sets up the parallel
# stack unless STACK=wheels is given (then the tests that need MPI-IO are skipped, saying so).
PY := .venv/bin/python
STACK ?= auto
TEST_STACK := $(if $(filter wheels,$(STACK)),wheels,parallel)
export NUMBA_CACHE_DIR := $(CURDIR)/.numba_cache
export OMP_NUM_THREADS := 1
export NUMBA_NUM_THREADS := 1
export OPENBLAS_NUM_THREADS := 1

.PHONY: setup run test test-all mutations loaded

setup:
	STACK=$(STACK) bash scripts/setup.sh

run: setup
	$(PY) -m ensemble run examples/small.toml -o small.h5 --force

test:
	STACK=$(TEST_STACK) bash scripts/setup.sh
	ENSEMBLE_TEST_STACK=$(TEST_STACK) $(PY) -m pytest -q -m "not slow"

test-all:
	STACK=$(TEST_STACK) bash scripts/setup.sh
	ENSEMBLE_TEST_STACK=$(TEST_STACK) $(PY) -m pytest -q

# plausible bugs applied one at a time to a copy of the repository; every one must be caught (tests/mutations.py)
mutations: setup
	$(PY) tests/mutations.py

# the suite five times in a row beside two CPU-bound processes: no test may hang or flake under load
loaded: setup
	bash tests/loaded.sh 5 2
