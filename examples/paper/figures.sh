#!/usr/bin/env bash
# The figures of docs/paper/ from the reduced summaries (docs/paper/*.summary.h5, committed): each
# panel's R(mu), and for Fig. 2 its recurrence times and R(mu). A few seconds each; reduce_full.sh
# runs it after reducing. Below each title, `analysis plot` states the events per point, mu_c,
# the window and the bands.
#   bash examples/paper/figures.sh [DIR]      (default docs/paper)
set -euo pipefail
cd "$(dirname "$0")/../.."
D=${1:-docs/paper}
PY=${PY:-.venv/bin/python}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache}
declare -A TITLE=(
  [fig1_b]="Fig. 1 top: R(mu) for b = 20..50 (a = 0, c = 1e3)"
  [fig1_a]="Fig. 1 middle: R(mu) for a = 0..30 (b = 50, c = 1e3)"
  [fig1_c]="Fig. 1 bottom: R(mu) for c = 1e2..1e4 (a = 0, b = 20)"
  [fig2]="Fig. 2: local recurrence times of large events (mu >= mu_c)"
  [large_b]="larger b: R(mu) for b = 60, 80, 100 (a = 0, c = 1e3)")
for name in fig1_b fig1_a fig1_c fig2 large_b; do
  s=$D/$name.summary.h5
  if [ ! -f "$s" ]; then
    echo "$name: $s not there: skipped"
    continue
  fi
  # regenerated: the old figures go first (plot keeps an existing file without --force)
  rm -f "$D/$name.png" "$D/${name}_magnitude.png"
  if [ "$name" = fig2 ]; then
    $PY -m analysis plot "$s" --figure recurrence -o "$D/fig2.png" --title "${TITLE[$name]}"
    $PY -m analysis plot "$s" --figure magnitude -o "$D/fig2_magnitude.png" --title "Fig. 2 points: R(mu)"
  else
    $PY -m analysis plot "$s" --figure magnitude -o "$D/$name.png" --title "${TITLE[$name]}"
  fi
done
