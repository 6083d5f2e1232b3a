#!/usr/bin/env bash
# The reductions, tables and figures of docs/populations.md, from the catalogs that
#   CONF=examples/populations OUT=runs/populations bash examples/paper/run_full.sh 2 regions short lengths discrete_l3 discrete_l6 discrete_l12
# writes. Summaries, tables and figures go to docs/populations/; the fault-by-fault summaries (large) stay in
# runs/populations/.   bash examples/populations/reduce.sh [NAME ...]   (default: every part)
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
RUNS=runs/populations
DOCS=docs/populations
export OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p "$DOCS"
PARTS=${*:-regions short lengths discreteness answer}
for name in $PARTS; do
  case $name in
    regions|short)
      $PY -m analysis reduce "$RUNS/$name.h5" --region --mu-bins 0:7:700 -o "$DOCS/$name.region.summary.h5" --force
      $PY -m analysis report "$DOCS/$name.region.summary.h5" > "$DOCS/$name.report.txt"
      $PY -m analysis reduce "$RUNS/$name.h5" --mu-bins 0:7:700 -o "$RUNS/$name.faults.summary.h5" --force
      $PY examples/populations/answer.py "$DOCS/$name.region.summary.h5" --faults "$RUNS/$name.faults.summary.h5" \
        -o "$DOCS/$name-answer" > /dev/null
      $PY examples/populations/figure.py "$DOCS/$name.region.summary.h5" "$DOCS/$name-answer.json" -o "$DOCS/$name.png"
      # where the long faults' large events lie, by length and b (lengths.py; the short run has too few long faults)
      if [ "$name" = regions ]; then
        $PY examples/populations/lengths.py "$RUNS/$name.h5" --fit-only > "$DOCS/$name.large_events.txt"
      fi
      # the transient, checked on the record: the first and the second half of every fault's window
      half=$($PY -c "import sys; from analysis import summary; print(min(summary.read(sys.argv[1])['points/region_span']) / 2)" \
             "$DOCS/$name.region.summary.h5")
      $PY -m analysis reduce "$RUNS/$name.h5" --region --region-span "$half" -o "$RUNS/$name.first.summary.h5" --force
      $PY -m analysis reduce "$RUNS/$name.h5" --region --region-span "$half" --region-skip "$half" \
        -o "$RUNS/$name.second.summary.h5" --force
      for part in first second; do
        $PY -m analysis report "$RUNS/$name.$part.summary.h5" > "$DOCS/$name.$part.report.txt"
      done
      ;;
    lengths)
      $PY examples/populations/lengths.py "$RUNS/lengths.h5" > "$DOCS/lengths.md"
      ;;
    discreteness)
      # the large-event threshold, GR's cut and the recurrence window scaled with the blocks per unit length (discreteness.py)
      for l in 3 6 12; do
        n=$((400 * l / 3))
        shift=$($PY -c "import math; print(math.log10($n / 400))")
        $PY -m analysis reduce "$RUNS/discrete_l$l.h5" --mu-c "$($PY -c "print(4 + $shift)")" \
          --b-cut "$($PY -c "print(3 + $shift)")" --window $((10 * n / 400)) -o "$DOCS/discrete_l$l.summary.h5" --force
      done
      $PY examples/populations/discreteness.py "$DOCS"/discrete_l{3,6,12}.summary.h5 > "$DOCS/discreteness.md"
      ;;
    answer)
      # the README's figure: the long faults' regions beside the short ones'
      $PY examples/populations/figure.py "$DOCS/regions.region.summary.h5" "$DOCS/regions-answer.json" \
        "$DOCS/short.region.summary.h5" "$DOCS/short-answer.json" --columns 3 -o "$DOCS/answer.png"
      ;;
    *) echo "error: unknown part $name (regions, short, lengths, discreteness, answer)" >&2; exit 2 ;;
  esac
done
