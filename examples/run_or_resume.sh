# Sourced by the example scripts that run long, resumable measurements (examples/*/run.sh):
#   run_or_resume CATALOG CONFIG [--set KEY=VALUE ...]
# skips a complete catalog, resumes an interrupted one (CATALOG.partial), else starts the run; on
# $RANKS ranks, appending the output to CATALOG's .log. Sets the one-thread environment of a run.
PY=.venv/bin/python
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-$PWD/.numba_cache} OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1

run_or_resume() {
  local out=$1 config=$2
  shift 2
  mkdir -p "$(dirname "$out")"
  if [ -f "$out" ]; then
    echo "$out: complete"
  elif [ -f "$out.partial" ]; then
    mpiexec -n "$RANKS" $PY -m ensemble resume "$out" 2>&1 | tee -a "${out%.h5}.log"
  else
    mpiexec -n "$RANKS" $PY -m ensemble run "$config" -o "$out" "$@" 2>&1 | tee -a "${out%.h5}.log"
  fi
}
