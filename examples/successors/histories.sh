#!/bin/bash
# The event histories behind docs/successors.md's figures. Usage: bash examples/successors/histories.sh [ranks]
# [out_dir] (from the repository root; out_dir defaults to runs/successors). An interrupted run is resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out"
py=.venv/bin/python
cat="$out/histories.h5"
. examples/successors/run_or_resume.sh
run_or_resume examples/successors/histories.toml "$cat" "$ranks"
# task 0 is b = 15, task 1 b = 20 (the sweep's order)
$py -m analysis history "$cat" --task 1 -o docs/successors/history_b20.png --force
$py -m analysis history "$cat" --task 0 -o docs/successors/history_b15.png --force
