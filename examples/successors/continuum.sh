#!/bin/bash
# The continuum-limit run behind docs/successors.md (L_0 against l). Usage: bash examples/successors/continuum.sh
# [ranks] [out_dir] (from the repository root; out_dir defaults to runs/successors). An interrupted run is resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out"
py=.venv/bin/python
cat="$out/continuum.h5"
. examples/successors/run_or_resume.sh
run_or_resume examples/successors/continuum.toml "$cat" "$ranks"
$py -m analysis reduce "$cat" -o docs/successors/continuum.summary.h5 --force
$py -m analysis report docs/successors/continuum.summary.h5 > docs/successors/continuum.report.txt
