#!/usr/bin/env bash
# Reduce, report and plot the slow-regime runs (runs/slow/*.h5 from
# `CONF=examples/slow OUT=runs/slow bash examples/paper/run_full.sh 2 b_sweep b18 b15`) into docs/slow/.
#   bash examples/slow/reduce.sh [RANKS]      (default 2; a minute)
# Per run: docs/slow/NAME.summary.h5 and its report NAME.txt; for the sweep also the figures
# b_sweep.png (R(mu) of the inertial events) and b_sweep_creep.png (creep episodes, aseismic fraction).
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
PY=${PY:-.venv/bin/python}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p docs/slow
for name in b_sweep b18 b15; do
  cat=runs/slow/$name.h5
  if [ ! -f "$cat" ]; then
    echo "$name: $cat not there (or not finished): skipped"
    continue
  fi
  out=docs/slow/$name
  mpiexec -n "$RANKS" $PY -m analysis reduce "$cat" -o "$out.summary.h5" --force
  $PY -m analysis report "$out.summary.h5" > "$out.txt"
done
if [ -f docs/slow/b_sweep.summary.h5 ]; then
  rm -f docs/slow/b_sweep.png docs/slow/b_sweep_creep.png
  $PY -m analysis plot docs/slow/b_sweep.summary.h5 --figure magnitude -o docs/slow/b_sweep.png \
    --title "Below the block stiffness 19: R(mu) of the inertial events, b = 10..20"
  $PY -m analysis plot docs/slow/b_sweep.summary.h5 --figure creep -o docs/slow/b_sweep_creep.png \
    --title "Creep episodes below the block stiffness, b = 10..18"
fi
