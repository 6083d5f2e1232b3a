#!/usr/bin/env bash
# The paper's comparison of friction laws, measured: the Carlson-Langer chain at the literature's
# setting (carlson_langer.toml: alpha = 1, 2, 3, four seeds of 2.5e5 events each) beside the aging law
# at b = 20 (aging_b20.toml: two seeds of 1e5 events) and Ruina's slip law at b = 20, a = 0 and 1
# (slip.toml: two seeds of 15000 rows each), all at N = 800, compared on the number of
# slipped blocks and the recurrence times over their median (analysis/compare.py, docs/laws.md).
#   bash examples/laws/compare.sh [RANKS]      (default 2; about 17 minutes of one core for the first two configs,
#   their headers, and 10 minutes on two ranks for slip.toml)
# Catalogs go to runs/laws/ (a complete one is reused, an interrupted one resumed); the table, its
# numbers and the figures to docs/laws/.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p runs/laws docs/laws
for name in carlson_langer aging_b20 slip; do
  out=runs/laws/$name.h5
  if [ -f "$out" ]; then
    echo "$name: $out is complete"
  elif [ -f "$out.partial" ]; then
    mpiexec -n "$RANKS" $PY -m ensemble resume "$out" 2>&1 | tee -a runs/laws/$name.log
  else
    mpiexec -n "$RANKS" $PY -m ensemble run examples/laws/$name.toml -o "$out" 2>&1 | tee -a runs/laws/$name.log
  fi
done
$PY -m analysis compare runs/laws/carlson_langer.h5 runs/laws/aging_b20.h5 runs/laws/slip.h5 -o docs/laws --force
