#!/usr/bin/env bash
# One catalog per integrator setting of examples/tolerance/base.toml, the tight reference first:
#   bash examples/tolerance/run.sh [RANKS]        (default 1; a few core-hours in all)
# A complete catalog is skipped and an interrupted one resumed, so the script can be stopped and
# started again at any time. The candidates run the config's root seed (the same initial states);
# the reference runs another (run.seed + 1), so that a candidate and the reference are independent
# samples, as benchmarks/statistics.py has them.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-1}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
mkdir -p runs/tolerance
SETTINGS="reference:ark4:1e-7 ark4-1e-3:ark4:1e-3 ark4-1e-4:ark4:1e-4 ark4-1e-5:ark4:1e-5 ark4-1e-6:ark4:1e-6 rk4-1e-3:rk4:1e-3"
for s in $SETTINGS; do
  IFS=: read -r name method value <<< "$s"
  if [ "$method" = rk4 ]; then set_value="integrator.dt=$value"; else set_value="integrator.rtol=$value"; fi
  if [ "$name" = reference ]; then seed="run.seed=8"; else seed="run.seed=7"; fi
  out=runs/tolerance/$name.h5
  if [ -f "$out" ]; then
    echo "$name: complete"
  elif [ -f "$out.partial" ]; then
    mpiexec -n "$RANKS" $PY -m ensemble resume "$out" 2>&1 | tee -a "runs/tolerance/$name.log"
  else
    mpiexec -n "$RANKS" $PY -m ensemble run examples/tolerance/base.toml -o "$out" \
      --set "integrator.method=\"$method\"" --set "$set_value" --set "$seed" 2>&1 | tee -a "runs/tolerance/$name.log"
  fi
done
