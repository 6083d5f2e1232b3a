#!/bin/bash
# The nucleation sweep behind docs/successors.md. Usage: bash examples/successors/nucleation.sh [ranks] [out_dir]
# (from the repository root; out_dir defaults to runs/successors). An interrupted run is resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out"
py=.venv/bin/python
cat="$out/nucleation.h5"
. examples/successors/run_or_resume.sh
# (a failed task would be reported and the others reduced as far as written)
run_or_resume examples/successors/nucleation.toml "$cat" "$ranks" || echo "note: a task failed; reducing the others"
part="$cat"; [ -e "$cat" ] || part="$cat.partial"
$py -m analysis reduce "$part" --partial -o docs/successors/nucleation.summary.h5 --force
$py -m analysis report docs/successors/nucleation.summary.h5 > docs/successors/nucleation.report.txt
