# Two entry points: `make run` (set up, run the example) and `make test` (set up, run the tests),
# and a quick tier, `make quick` (about a minute of tests touching every module; docs/tests.md).
# STACK (scripts/setup.sh): auto (default: the stack .venv has, else the wheel stack, ready in
# about a minute), parallel (build mpi4py and h5py against the machine's MPI and parallel HDF5:
# minutes) or wheels. `make test` tests the parallel writer, so it sets up the parallel stack
# unless STACK=wheels is given (then the tests that need MPI-IO are skipped, saying so); `make run`
# and `make quick` then keep it. Numba's cache is the package's own (ensemble/kernel_cache.py: the
# checkout's .numba_cache unless NUMBA_CACHE_DIR is set), the same for make and a direct
# `python -m ensemble`, so the kernels are compiled once.
PY := .venv/bin/python
STACK ?= auto
# `make test` runs the test files on this many pytest workers (pytest-xdist; a file's tests stay on one worker, so
# its module fixtures are made once; in tests/conftest.py's order, the longest files first): 2 halves the suite's time
# on a 2-core machine (docs/tests.md); 1 runs it serially
TEST_WORKERS ?= 2
XDIST := $(if $(filter 1,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder)
TEST_STACK := $(if $(filter wheels,$(STACK)),wheels,parallel)
export OMP_NUM_THREADS := 1
export NUMBA_NUM_THREADS := 1
export OPENBLAS_NUM_THREADS := 1

.PHONY: setup run test quick slow test-all lint mutations loaded

setup:
	STACK=$(STACK) bash scripts/setup.sh

run: setup
	$(PY) -m ensemble run examples/small.toml -o small.h5 --force

test:
	STACK=$(TEST_STACK) bash scripts/setup.sh
	ENSEMBLE_TEST_STACK=$(TEST_STACK) $(PY) -m pytest -q -m "not slow" $(XDIST) --durations=30

# a tier of about a minute that touches every module (the `quick` marker: tests/conftest.py), on TEST_WORKERS
quick: setup
	$(PY) -m pytest -q -m "quick and not slow" $(XDIST)

# the slower tier: the tests marked slow (the Slurm cluster, the longest runs, compiling into empty caches),
# which CI runs after `make test` (docs/tests.md)
slow:
	STACK=$(TEST_STACK) bash scripts/setup.sh
	ENSEMBLE_TEST_STACK=$(TEST_STACK) $(PY) -m pytest -q -m slow $(XDIST) -rs --durations=20

test-all:
	STACK=$(TEST_STACK) bash scripts/setup.sh
	ENSEMBLE_TEST_STACK=$(TEST_STACK) $(PY) -m pytest -q

# ruff over the repository (pyproject.toml [tool.ruff]: the rules, and why each ignore): unused imports and
# variables, undefined names, layout, blind excepts, stale noqa; `make setup` installs ruff with the test tools
lint: setup
	$(PY) -m ruff check .

# plausible bugs applied one at a time to a copy of the repository; every one must be caught (tests/mutations.py)
mutations: setup
	$(PY) tests/mutations.py

# make test's suite twice in a row beside two CPU-bound processes: no test may hang or flake under load
loaded: setup
	bash tests/loaded.sh 2 2
