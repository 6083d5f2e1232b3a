#!/usr/bin/env bash
# The reduced paper runs (4 seeds x 2000-3000 events after 1000 per point) on this machine's ranks,
# reduced, reported and plotted into runs/reduced/ (git-ignored): a quick look at every panel, about
# 25 minutes on 2 cores. The full-size runs are run_full.sh and reduce_full.sh (docs/paper.md).
#   bash examples/paper/run_reduced.sh [RANKS]      (default 2)
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
out=runs/reduced
mkdir -p $out
for name in fig1_b fig1_a fig1_c fig2; do
  cfg=examples/paper/${name}_reduced.toml
  if [ ! -f $out/$name.h5 ]; then
    mpiexec -n "$RANKS" $PY -m ensemble run "$cfg" -o $out/$name.h5 --set output.progress_seconds=60
  fi
  mpiexec -n "$RANKS" $PY -m analysis reduce $out/$name.h5 -o $out/$name.summary.h5 --force
  $PY -m analysis report $out/$name.summary.h5 > $out/$name.txt
done
# the paper's claims beside the reduced numbers, labelled reduced (docs/paper.md)
$PY -m analysis paper $out/fig1_b.summary.h5 $out/fig1_a.summary.h5 $out/fig1_c.summary.h5 \
  $out/fig2.summary.h5 > $out/paper.txt
rm -f $out/*.png     # plot keeps an existing figure
for name in fig1_b fig1_a fig1_c; do
  $PY -m analysis plot $out/$name.summary.h5 --figure magnitude -o $out/$name.png \
    --title "$name (reduced run): R(mu), 95% bootstrap bands"
done
$PY -m analysis plot $out/fig2.summary.h5 --figure recurrence -o $out/fig2.png \
  --title "fig2 (reduced run): local recurrence times of mu >= 4 events, window 10 blocks"
echo "wrote $out/: catalogs, summaries, reports (*.txt), the claims (paper.txt) and figures (*.png)"
