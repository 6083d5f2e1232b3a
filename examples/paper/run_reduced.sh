#!/usr/bin/env bash
# The reduced paper runs on this machine's ranks, reduced and plotted into docs/figures/.
#   bash examples/paper/run_reduced.sh [RANKS]      (default 2; about 20 minutes on 2 cores)
# Catalogs and summaries go to runs/ (git-ignored); figures and reports to docs/figures/.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p runs docs/figures
for name in fig1_b fig1_a fig1_c fig2; do
  cfg=examples/paper/${name}_reduced.toml
  if [ ! -f runs/$name.h5 ]; then
    mpiexec -n "$RANKS" $PY -m ensemble run "$cfg" -o runs/$name.h5 --set output.progress_seconds=60
  fi
  mpiexec -n "$RANKS" $PY -m analysis reduce runs/$name.h5 -o runs/$name.summary.h5 --force
  $PY -m analysis report runs/$name.summary.h5 > docs/figures/$name.txt
done
for name in fig1_b fig1_a fig1_c; do
  $PY -m analysis plot runs/$name.summary.h5 --figure magnitude -o docs/figures/$name.png \
    --title "$name (reduced run): R(mu), 95% bootstrap bands over seeds"
done
$PY -m analysis plot runs/fig2.summary.h5 --figure recurrence -o docs/figures/fig2.png \
  --title "fig2 (reduced run): local recurrence times of mu >= 4 events, window 10 blocks"
$PY -m analysis plot runs/fig2.summary.h5 --figure magnitude -o docs/figures/fig2_magnitude.png \
  --title "fig2 (reduced run): R(mu)"
