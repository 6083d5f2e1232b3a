#!/usr/bin/env bash
# Branching, measured (issue 14, item 2): the pooled statistics of 4 seeds branched from one spin-up
# per point against 4 independent seeds (examples/tolerance's ark4 rtol 1e-5 catalog, the same
# integrator) and against one long trajectory with as many events:
#   bash examples/branch/run.sh [RANKS]      (about an hour of one core; resumable like examples/tolerance)
# The independent seeds are the reference of benchmarks/statistics.py's catalog mode (their noise
# floor); results in benchmarks/results/branching_N800_b{20,50}.{txt,json,png}.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-1}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p runs/branch
for name in branched long; do
  out=runs/branch/$name.h5
  if [ -f "$out" ]; then
    echo "$name: complete"
  elif [ -f "$out.partial" ]; then
    mpiexec -n "$RANKS" $PY -m ensemble resume "$out" 2>&1 | tee -a "runs/branch/$name.log"
  else
    mpiexec -n "$RANKS" $PY -m ensemble run "examples/branch/$name.toml" -o "$out" 2>&1 | tee -a "runs/branch/$name.log"
  fi
done
if [ ! -f runs/tolerance/ark4-1e-5.h5 ] || [ ! -f runs/tolerance/reference.h5 ]; then
  echo "runs/tolerance/{ark4-1e-5,reference}.h5 missing: they come from bash examples/tolerance/run.sh" >&2
  exit 1
fi
# the noise floor: the independent seeds' halves, and those of examples/tolerance's reference (rtol 1e-7,
# whose statistics equal rtol 1e-5's at this size) with its distance from them
$PY -m benchmarks.statistics --catalogs runs/tolerance/ark4-1e-5.h5 runs/branch/branched.h5 runs/branch/long.h5 \
  --label "independent seeds" branched "one trajectory" --rerun runs/tolerance/reference.h5 --name branching
# and the branched seeds as the reference: one trajectory against them (their halves as the floor)
$PY -m benchmarks.statistics --catalogs runs/branch/branched.h5 runs/branch/long.h5 runs/tolerance/ark4-1e-5.h5 \
  --label branched "one trajectory" "independent seeds" --rerun runs/tolerance/reference.h5 --name branched_reference
