#!/usr/bin/env bash
# The suite on a loaded machine: RUNS runs in a row of the README's test command (make test's pytest: all but
# the slow tier, on TEST_WORKERS workers), each beside BURNERS CPU-bound processes (`python3 -c 'while 1: pass'`),
# started before and stopped after every run: on 2 cores a load of 4. Stops at the first failing run; a summary
# line per run goes to stdout.
#   bash tests/loaded.sh [RUNS] [BURNERS]        (default 2 runs, 2 burners; `make loaded`)
# Processes already busy on the machine (a long run, say) add to the load.
set -uo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-2}
BURNERS=${2:-2}
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1
pids=()
stop_burners() { [ ${#pids[@]} -gt 0 ] && kill "${pids[@]}" 2>/dev/null; wait "${pids[@]}" 2>/dev/null; pids=(); }
trap stop_burners EXIT
for i in $(seq 1 "$RUNS"); do
  for _ in $(seq 1 "$BURNERS"); do python3 -c 'while 1: pass' & pids+=($!); done
  start=$(date +%s)
  $PY -m pytest -q -m "not slow" -n "${TEST_WORKERS:-2}" --dist loadfile -p no:cacheprovider > "${LOADED_LOG:-/tmp}/loaded_run_$i.log" 2>&1
  rc=$?
  stop_burners
  echo "run $i of $RUNS: exit $rc in $(( $(date +%s) - start )) s, load average $(cut -d' ' -f1-3 /proc/loadavg)," \
       "$(tail -n 1 "${LOADED_LOG:-/tmp}/loaded_run_$i.log")"
  [ $rc -eq 0 ] || exit $rc
done
