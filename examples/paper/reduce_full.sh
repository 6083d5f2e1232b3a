#!/usr/bin/env bash
# Reduce, report and plot the full-size paper runs (runs/paper/*.h5 from run_full.sh) into docs/paper/.
#   bash examples/paper/reduce_full.sh [RANKS]      (default 2; a few minutes)
# Per panel: docs/paper/PANEL.summary.h5, the report PANEL.txt and the figure PANEL.png (fig2 also
# fig2_magnitude.png; examples/paper/figures.sh); a panel whose catalog is not complete is skipped.
# When every panel is there, all.summary.h5 / all.txt reduce them together (points that panels share pool: b = 20 from
# fig1_b, fig1_c and fig2, b = 50 from fig1_b and fig1_a). tables.md (examples/paper/tables.py):
# each run's tasks with events, wall time and events/s, and the paper's claims beside the numbers.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-2}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
PANELS="fig1_b fig1_a fig1_c fig2 large_b"
mkdir -p docs/paper
done_panels=()
for name in $PANELS; do
  cat=runs/paper/$name.h5
  if [ ! -f "$cat" ]; then
    echo "$name: $cat not there (or not finished): skipped"
    continue
  fi
  done_panels+=("$cat")
  out=docs/paper/$name
  mpiexec -n "$RANKS" $PY -m analysis reduce "$cat" -o "$out.summary.h5" --force
  $PY -m analysis report "$out.summary.h5" > "$out.txt"
done
PY=$PY bash examples/paper/figures.sh docs/paper
if [ ${#done_panels[@]} -eq 5 ]; then
  mpiexec -n "$RANKS" $PY -m analysis reduce "${done_panels[@]}" -o docs/paper/all.summary.h5 --force
  $PY -m analysis report docs/paper/all.summary.h5 > docs/paper/all.txt
fi
$PY examples/paper/tables.py docs/paper > docs/paper/tables.md
echo "wrote docs/paper/ for: ${done_panels[*]:-nothing}"
