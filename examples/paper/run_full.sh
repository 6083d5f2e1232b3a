#!/usr/bin/env bash
# The paper's runs at full size (2e5 events after 1e4 per point), one catalog per panel under runs/paper/.
#   bash examples/paper/run_full.sh [RANKS] [PANEL ...]     (default 2 ranks; all panels)
# A panel whose catalog is complete is skipped; one that was interrupted (a .partial is left) is continued
# with `ensemble resume`, so the script can be stopped and started again at any time.
# Each panel has its own root seed, so the points that panels share (b = 20, c = 1e3, N = 800 in fig1_b,
# fig1_c and fig2) are independent trajectories that `analysis reduce` can pool.
# Reduce and plot afterwards with examples/paper/reduce_full.sh.
# Another folder of configs: CONF=examples/slow OUT=runs/slow bash examples/paper/run_full.sh 2 b_sweep b18 b15
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
shift || true
PANELS=${*:-fig1_b fig1_a fig1_c fig2 large_b}
CONF=${CONF:-examples/paper}
OUT=${OUT:-runs/paper}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p "$OUT"
for name in $PANELS; do
  out=$OUT/$name.h5
  if [ -f "$out" ]; then
    echo "$name: $out is complete"
  elif [ -f "$out.partial" ]; then
    mpiexec -n "$RANKS" $PY -m ensemble resume "$out" --set output.progress_seconds=300 2>&1 | tee -a "$OUT/$name.log"
  else
    mpiexec -n "$RANKS" $PY -m ensemble run "$CONF/$name.toml" -o "$out" \
      --set output.progress_seconds=300 2>&1 | tee -a "$OUT/$name.log"
  fi
done
