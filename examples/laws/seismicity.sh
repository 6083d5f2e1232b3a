#!/bin/bash
# The seismicity around large events of the friction laws' comparison catalogs (docs/laws.md, "Seismicity
# around large events"): each law at its own scale (mu_c: the law's default, Carlson-Langer mu >= 1, aging
# mu >= 4), the Carlson-Langer chain on its own time and length scales (T nu of 1e-3 per event, the doughnut
# within a few blocks), the aging law with the defaults chosen for it. Run from the repository root, after
# examples/laws/compare.sh (RUNS: where its catalogs are; OUT: where the summaries go).
set -euo pipefail
RUNS=${RUNS:-runs/laws}
OUT=${OUT:-$RUNS}
PY=${PY:-.venv/bin/python}
$PY -m analysis reduce "$RUNS/carlson_langer.h5" -o "$OUT/carlson_langer.seismicity.summary.h5" --force \
    --seis-time-bins=-0.1:0.1:80 --seis-distance-bins 0:20:20 \
    --seis-near 1 --seis-ring 4 --seis-short 0.01 --seis-long 0.1
$PY -m analysis reduce "$RUNS/aging_b20.h5" -o "$OUT/aging_b20.seismicity.summary.h5" --force
$PY -m analysis report "$OUT/carlson_langer.seismicity.summary.h5"
$PY -m analysis report "$OUT/aging_b20.seismicity.summary.h5"
$PY -m analysis plot "$OUT/carlson_langer.seismicity.summary.h5" "$OUT/aging_b20.seismicity.summary.h5" \
    --figure seismicity -o docs/laws/seismicity.png --force
