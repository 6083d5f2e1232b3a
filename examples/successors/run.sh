#!/bin/bash
# The runs and reductions behind docs/successors.md. Usage: bash examples/successors/run.sh [ranks] [out_dir]
# (from the repository root; out_dir defaults to runs/successors). An interrupted run is resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out"
py=.venv/bin/python
cat="$out/ruptures.h5"
. examples/successors/run_or_resume.sh
run_or_resume examples/successors/ruptures.toml "$cat" "$ranks"
$py -m analysis reduce "$cat" -o docs/successors/ruptures.summary.h5 --force
for lo in 50 300; do      # the L_0 fit's lower end: its sensitivity (docs/successors.md)
    $py -m analysis reduce "$cat" -o "$out/ruptures_lr$lo.summary.h5" --lr-min $lo --force
    $py -m analysis report "$out/ruptures_lr$lo.summary.h5" | grep -E "^point|L_0" > docs/successors/lr_min_$lo.txt
done
$py -m analysis report docs/successors/ruptures.summary.h5 > docs/successors/ruptures.report.txt
for figure in rupture_length rupture_classes; do
    $py -m analysis plot docs/successors/ruptures.summary.h5 --figure $figure -o docs/successors/$figure.png --force
done
