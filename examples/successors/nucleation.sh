#!/bin/bash
# The nucleation sweep behind docs/successors.md. Usage: bash examples/successors/nucleation.sh [ranks] [out_dir]
# (from the repository root; out_dir defaults to runs/successors). An interrupted run is resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out"
py=.venv/bin/python
cat="$out/nucleation.h5"
if [ -e "$cat.partial" ]; then
    mpirun -n "$ranks" $py -m ensemble resume "$cat"
elif [ ! -e "$cat" ]; then
    mpirun -n "$ranks" $py -m ensemble run examples/successors/nucleation.toml -o "$cat"
fi
$py -m analysis reduce "$cat" -o docs/successors/nucleation.summary.h5 --force
$py -m analysis report docs/successors/nucleation.summary.h5 > docs/successors/nucleation.report.txt
