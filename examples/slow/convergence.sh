#!/usr/bin/env bash
# The creep statistics against integrator.creep_tol (1e-5, 1e-6, 1e-7) and the event integrator's rtol
# (1e-4, 1e-6): five runs of examples/slow/convergence.toml into runs/slow/convergence/, reduced, and the
# table docs/slow/convergence.md. 1184 s of one core here (74 to 502 s per run, a shared machine).
#   bash examples/slow/convergence.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${PY:-.venv/bin/python}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
D=runs/slow/convergence
mkdir -p "$D"
labels=()
for setting in "creep_tol=1e-5" "creep_tol=1e-6" "creep_tol=1e-7" "rtol=1e-6" "creep_tol=1e-7 rtol=1e-6"; do
  name=${setting//[ =]/_}
  sets=()
  for s in $setting; do sets+=(--set "integrator.$s"); done
  [ -f "$D/$name.h5" ] || $PY -m ensemble run examples/slow/convergence.toml -o "$D/$name.h5" "${sets[@]}"
  $PY -m analysis reduce "$D/$name.h5" -o "$D/$name.summary.h5" --force > /dev/null
  labels+=("$setting=$D/$name.summary.h5")
done
{
  echo "# Creep statistics against the integrators' tolerances"
  echo
  echo "\`bash examples/slow/convergence.sh\`: b = 15, N = 100, 4 seeds x 5000 rows after 1000 (examples/slow/convergence.toml);"
  echo "defaults creep_tol = 1e-6, rtol = 1e-4. 95% bootstrap intervals (analysis reduce: below 10 seeds, over stretches of each trajectory)."
  echo
  $PY examples/slow/convergence.py "${labels[@]}"
} > docs/slow/convergence.md
cat docs/slow/convergence.md
