#!/bin/bash
# The slow-slip regime maps behind docs/successors.md. Usage: bash examples/successors/slow_slip.sh [ranks] [out_dir]
# (from the repository root; out_dir defaults to runs/successors). Interrupted runs are resumed.
set -euo pipefail
ranks=${1:-2}
out=${2:-runs/successors}
mkdir -p "$out" docs/successors
py=.venv/bin/python
. examples/successors/run_or_resume.sh
for l in 3 12; do
  for nu in 1e-8 1e-4; do
    name="slow_slip_l${l}_nu${nu}"
    run_or_resume examples/successors/slow_slip.toml "$out/$name.h5" "$ranks" --set "model.l=$l" --set "model.nu=$nu" \
      || echo "note: a task of $name failed; reducing the others"
    part="$out/$name.h5"; [ -e "$part" ] || part="$part.partial"
    $py -m analysis reduce "$part" --partial -o "docs/successors/$name.summary.h5" --force
    $py -m analysis report "docs/successors/$name.summary.h5" > "docs/successors/$name.report.txt"
    $py -m analysis plot "docs/successors/$name.summary.h5" --figure slow_slip -o "docs/successors/$name.png" --force
  done
done
