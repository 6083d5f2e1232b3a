#!/usr/bin/env bash
# Branching, measured (issue 14, item 2): the pooled statistics of 4 seeds branched from one spin-up
# per point against 4 independent seeds (examples/tolerance's ark4 rtol 1e-5 catalog, the same
# integrator) and against one long trajectory with as many events:
#   bash examples/branch/run.sh [RANKS]      (about an hour of one core; resumable like examples/tolerance)
# The independent seeds are the reference of benchmarks/statistics.py's catalog mode (their noise
# floor); results in benchmarks/results/branching_N800_b{20,50}.{txt,json,png}.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-1}
. examples/run_or_resume.sh
for name in branched long; do
  run_or_resume "runs/branch/$name.h5" "examples/branch/$name.toml"
done
if [ ! -f runs/tolerance/ark4-1e-5.h5 ] || [ ! -f runs/tolerance/reference.h5 ]; then
  echo "runs/tolerance/{ark4-1e-5,reference}.h5 missing: they come from bash examples/tolerance/run.sh" >&2
  exit 1
fi
# the noise floor: the independent seeds' halves, and those of examples/tolerance's reference (rtol 1e-7,
# whose statistics equal rtol 1e-5's at this size) with its distance from them
$PY -m benchmarks.statistics --catalogs runs/tolerance/ark4-1e-5.h5 runs/branch/branched.h5 runs/branch/long.h5 \
  --label "independent seeds" branched "one trajectory" --rerun runs/tolerance/reference.h5 --name branching
# and the branched seeds as the reference: one trajectory against them (their halves as the floor)
$PY -m benchmarks.statistics --catalogs runs/branch/branched.h5 runs/branch/long.h5 runs/tolerance/ark4-1e-5.h5 \
  --label branched "one trajectory" "independent seeds" --rerun runs/tolerance/reference.h5 --name branched_reference
