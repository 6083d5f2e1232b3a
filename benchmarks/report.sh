#!/usr/bin/env bash
# The benchmark report of "Speed against error", rerunnable with one command from the repository root:
#
#     bash benchmarks/report.sh [OUT]          # OUT defaults to benchmarks/results
#
# Runs every benchmark at its default (paper-setting) sizes, one after the other on one core, and
# writes tables (.txt), data (.json) and figures (.png) into OUT. Expected duration on this
# machine: about 60 min in all (work precision ~5-10 min, statistics ~25 min,
# cost scaling ~15-20 min, step budget ~4 min, step trace ~1 min, hard cases ~10 min, throughput ~3 min). Environment: PY (python,
# default .venv/bin/python), JOBS (processes for the statistics run, default 1; 2 halves its time but
# then two runs share the machine's cores, so its events/s are per process under that load).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-benchmarks/results}
PY=${PY:-.venv/bin/python}
JOBS=${JOBS:-1}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 \
       OPENBLAS_NUM_THREADS=1 PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH}
mkdir -p "$OUT"
start=$SECONDS
step() { echo "== $* ($(( (SECONDS - start) / 60 )) min elapsed)"; }

step "work precision, single events, b = 20 and 50"
"$PY" -m benchmarks.work_precision --out "$OUT"
step "statistical error against speed"
"$PY" -m benchmarks.statistics --jobs "$JOBS" --out "$OUT"
step "cost per event against N and b"
"$PY" -m benchmarks.cost_scaling --out "$OUT"
step "step budget: block-steps per slid block and cost per block-step"
"$PY" -m benchmarks.step_budget --out "$OUT"
"$PY" -m benchmarks.step_budget --b 50 --out "$OUT"
step "step trace: what limits the adaptive step (b = 20 and 50)"
"$PY" -m benchmarks.step_trace --out "$OUT"
"$PY" -m benchmarks.step_trace --b 50 --out "$OUT"
step "hard cases at full size, rk4 and ark4 untuned"
"$PY" -m benchmarks.hard_cases --out "$OUT"
step "throughput of the paper setting"
"$PY" benchmarks/throughput.py | tee "$OUT/throughput.txt"
step "throughput of the friction laws (docs/laws.md)"
{ "$PY" benchmarks/throughput.py --method ark4
  for alpha in 1 2 3; do
    "$PY" benchmarks/throughput.py --law carlson-langer --alpha $alpha --nu 0.01 --method ark4 --transient 100000 --events 100000
  done
  "$PY" benchmarks/throughput.py --law carlson-langer --alpha 3 --nu 0.01 --method rk4 --transient 100000 --events 100000
} | tee "$OUT/throughput_laws.txt"
step "done: results in $OUT"
