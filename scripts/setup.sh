#!/usr/bin/env bash
# Idempotent setup of .venv in the repository root, with one of two stacks (docs/install.md):
#
#   parallel  mpi4py and h5py built against an MPI and a parallel HDF5 already on this machine
#             (modules, Spack, conda, Debian packages), found by scripts/stack.py. As root on Debian
#             with none found, MPICH and parallel HDF5 are installed from Debian first. Runs with
#             more than one rank write the catalog through MPI-IO (the parallel writer). Minutes:
#             mpi4py and h5py are compiled.
#   wheels    no root, no compiler, no MPI on the machine: MPICH from the `mpich` wheel, the mpi4py
#             and h5py wheels (h5py without MPI: runs with more ranks use the rank-0 writer). About
#             a minute.
#
# STACK=auto (default; `make run`) keeps the stack .venv has, else takes wheels, saying whether a
# parallel stack could be built here (a parallel .venv that no longer imports is rebuilt, falling
# back to wheels). STACK=parallel (`make test`) builds it or fails, installing Debian's packages as
# root when none is found; STACK=wheels does not look. PYTHON picks the interpreter (default
# python3, >= 3.11). .venv/ensemble-stack names the stack once it is complete and checked; until
# then a rerun starts over, so an interrupted or failed setup leaves nothing that a run would use.
# Last, every friction law's kernels are compiled into the package's numba cache (`python -m ensemble
# compile`: about a minute a law, as many at once as there are cores), so that no first run compiles.
# A second run only checks (a few seconds). Every stage prints a line with the time since setup
# started, and long steps a "still ..." line every SETUP_HEARTBEAT seconds (default 30).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
STACK=${STACK:-auto}
PY=${PYTHON:-python3}
VPY=.venv/bin/python
STATE=.venv/ensemble-stack
LOG=.venv/setup-build.log

HEARTBEAT=${SETUP_HEARTBEAT:-30}
T0=$SECONDS

say() { echo "setup: $*"; }
die() { echo "setup: error: $*" >&2; exit 1; }
elapsed() { local s=$((SECONDS - T0)); printf '%d:%02d' $((s / 60)) $((s % 60)); }
STAGE=0
STAGES=0
stage() {   # "[k/n] what (elapsed m:ss)"; unnumbered when the stages are not counted (a recheck)
  STAGE=$((STAGE + 1))
  if [ "$STAGES" -gt 0 ]; then say "[$STAGE/$STAGES] $* (elapsed $(elapsed))"; else say "$* (elapsed $(elapsed))"; fi
}
BEAT=
stop_beat() {
  if [ -n "$BEAT" ]; then kill "$BEAT" 2>/dev/null || true; wait "$BEAT" 2>/dev/null || true; BEAT=; fi
}
trap stop_beat EXIT
step() {   # step WHAT CMD...: CMD's output into $STEP_LOG (default $LOG), shown only if it fails;
  # meanwhile "still WHAT" every $HEARTBEAT s, so that a long build is never silent. The beat's
  # sleep gets no stdout and is killed with it: nothing may hold a pipe such as `make | tee` open.
  local what=$1 log=${STEP_LOG:-$LOG} rc=0
  shift
  ( s=; trap '[ -z "$s" ] || kill "$s" 2>/dev/null; exit 0' TERM
    while :; do
      sleep "$HEARTBEAT" </dev/null >/dev/null 2>&1 & s=$!
      wait "$s"
      say "  ... still $what, $(elapsed) elapsed"
    done ) &
  BEAT=$!
  "$@" >>"$log" 2>&1 || rc=$?
  stop_beat
  if [ "$rc" != 0 ]; then
    say "failed: $what ($*); the end of $log:"
    tail -n 15 "$log" | sed 's/^/  /'
  fi
  return "$rc"
}

case $STACK in auto|parallel|wheels) ;; *) die "STACK=$STACK: must be auto, parallel or wheels" ;; esac
command -v "$PY" >/dev/null 2>&1 || die "PYTHON=$PY: not found (this project needs Python >= 3.11)"
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
  || die "$PY is $("$PY" -V 2>&1); this project needs Python >= 3.11 (PYTHON=/path/to/python3.11 make ...)"

has_mpi_h5py() { $VPY -c "import h5py, sys; sys.exit(0 if h5py.get_config().mpi else 1)" 2>/dev/null; }
stack_works() {   # the stack named in $STATE is importable as that stack
  case $1 in
    parallel) has_mpi_h5py && $VPY -c "import mpi4py.MPI" 2>/dev/null ;;
    wheels) $VPY -m pip show -q mpich >/dev/null 2>&1 && $VPY -c "import mpi4py.MPI, h5py" 2>/dev/null ;;
    *) return 1 ;;
  esac
}

install_project() {
  # (an editable install maps the packages that existed when it ran: check from outside the tree)
  local stamp=.venv/.ensemble-installed
  if [ ! -f "$stamp" ] || [ setup.cfg -nt "$stamp" ] || [ pyproject.toml -nt "$stamp" ] \
     || ! (cd / && "$ROOT/$VPY" -c "import ensemble, analysis") 2>/dev/null; then
    stage "installing the project (editable) with numpy, numba, matplotlib and the test tools"
    step "installing the project" \
      $VPY -m pip install --only-binary=numpy,numba,llvmlite,matplotlib,scipy --no-build-isolation -e ".[test]"
    touch "$stamp"
  fi
}

compile_kernels() {   # every friction law's kernels into the package's numba cache (ensemble/compiled.py)
  local out rc=0
  stage "compiling the kernels of every friction law on every geometry (about a minute a pair where not yet compiled, as many at once as there are cores; seconds when cached)"
  out=$(mktemp)
  STEP_LOG=$out step "compiling the kernels" $VPY -m ensemble compile || rc=$?
  grep '^model.law' "$out" | sed 's/^/  /' || true
  rm -f "$out"
  [ "$rc" = 0 ] || die "compiling the kernels failed (above); runs would compile them themselves"
}

report() {   # in validate's words (ensemble/environment.py): the MPI, the HDF5, the writer runs take
  echo "setup: ok: stack $1 ($(elapsed))"
  $VPY -c "from ensemble import environment; print('\n'.join('  ' + line for line in environment.describe('auto')))"
}

# -- a complete stack already there: check and leave -----------------------------------------------
current=$(cat "$STATE" 2>/dev/null || true)
if [ -n "$current" ] && { [ "$STACK" = auto ] || [ "$STACK" = "$current" ]; } && stack_works "$current"; then
  install_project
  compile_kernels
  report "$current"
  exit 0
fi

build_parallel() {   # against $STACK_MPICC and $STACK_H5PY_ENV; output in $LOG
  say "building against $STACK_MPICC and $STACK_HDF5 (several minutes; log: $LOG)"
  # the wheel's mpiexec and libmpi would shadow the MPI these are built against
  $VPY -m pip uninstall -q -y mpich >>"$LOG" 2>&1 || true
  stage "building mpi4py against $STACK_MPICC"
  step "building mpi4py" \
    env MPICC="$STACK_MPICC" $VPY -m pip install --no-binary=mpi4py --force-reinstall --no-deps mpi4py || return 1
  stage "building h5py against $STACK_HDF5 (with MPI)"
  step "installing h5py's build tools" $VPY -m pip install numpy "Cython>=0.29.31" pkgconfig || return 1
  step "building h5py" \
    env CC="$STACK_MPICC" HDF5_MPI=ON "$STACK_H5PY_ENV" $VPY -m pip install --no-binary=h5py --no-build-isolation --force-reinstall --no-deps h5py \
    || return 1
  has_mpi_h5py || { say "h5py was built but has no MPI support"; return 1; }
  local mpiexec tmp
  stage "checking that 2 ranks write one file through MPI-IO"
  mpiexec=$(dirname "$STACK_MPICC")/mpiexec
  [ -x "$mpiexec" ] || mpiexec=$(command -v mpiexec || true)
  if [ -z "$mpiexec" ]; then
    say "no mpiexec beside $STACK_MPICC or on PATH: the 2-rank MPI-IO check is left to the first run"
    return 0
  fi
  tmp=$(mktemp -d)
  if ! step "the 2-rank MPI-IO check" timeout 120 "$mpiexec" -n 2 $VPY scripts/stack.py --check-mpio "$tmp"; then
    rm -rf "$tmp"
    return 1
  fi
  rm -rf "$tmp"
  say "$(tail -n 1 "$LOG")"
}

install_wheels() {
  stage "installing the wheel stack: MPICH from the mpich wheel, mpi4py and h5py (without MPI) wheels"
  step "installing the wheels" \
    $VPY -m pip install --only-binary=:all: --force-reinstall --no-deps "mpi4py>=4.1" mpich h5py
  step "installing the wheels' dependencies" $VPY -m pip install --only-binary=:all: "mpi4py>=4.1" mpich h5py
}

# -- which stack: decided before .venv is touched, so that a refusal changes nothing ---------------
# auto builds the parallel stack only where one was built before (and no longer imports); a new
# .venv gets the wheels in about a minute, with a word on the parallel stack if one could be built.
kind=wheels
want=$STACK
[ "$STACK" = auto ] && [ "$current" = parallel ] && want=parallel
debian_root() { [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && [ -r /etc/debian_version ]; }
if [ "$STACK" != wheels ]; then
  eval "$("$PY" scripts/stack.py)"
  apt=0
  [ "$STACK_FOUND" = 0 ] && [ "$STACK" = parallel ] && debian_root && apt=1
  if [ "$want" = parallel ]; then   # venv and pip, [Debian], mpi4py, h5py, the MPI-IO check, the project
    STAGES=$((6 + apt))
  else
    STAGES=4                        # venv and pip, the wheels, the project, the kernels
  fi
  if [ "$apt" = 1 ]; then
    say "no parallel HDF5 stack found (missing $STACK_MISSING); as root on Debian: installing MPICH and parallel HDF5"
    stage "installing mpich libmpich-dev libhdf5-mpich-dev pkg-config from Debian (apt-get)"
    apt_log=$(mktemp)
    STEP_LOG=$apt_log step "installing Debian's MPICH and parallel HDF5" \
      env DEBIAN_FRONTEND=noninteractive sh -c 'apt-get update -qq && apt-get install -y -qq \
        --no-install-recommends mpich libmpich-dev libhdf5-mpich-dev pkg-config' \
      || die "apt-get failed (its output above)"
    rm -f "$apt_log"
    eval "$("$PY" scripts/stack.py)"
  fi
  why="no parallel HDF5 stack: missing $STACK_MISSING"
  why="$why (python3 scripts/stack.py --explain shows where setup looked)"
  if [ "$want" = parallel ] && [ "$STACK_FOUND" = 1 ]; then
    kind=parallel
  elif [ "$STACK" = parallel ]; then
    die "STACK=parallel: $why. Load an MPI and a parallel HDF5 (module load ..., spack load ...; docs/install.md), or set STACK=wheels"
  elif [ "$want" = parallel ]; then
    say "$why"
    say "falling back to the wheel stack: runs work on any number of ranks, rank 0 writing the catalog"
    STAGES=4
  elif [ "$STACK_FOUND" = 1 ]; then
    say "the wheel stack (about a minute): runs work on any number of ranks, rank 0 writing the catalog"
    say "a parallel HDF5 stack is on this machine ($STACK_MPICC, $STACK_HDF5): for the MPI-IO writer"
    say "  (many ranks on a parallel file system) build against it: make setup STACK=parallel (several minutes)"
  else
    say "$why"
    say "falling back to the wheel stack: runs work on any number of ranks, rank 0 writing the catalog"
  fi
else
  STAGES=4
fi

stage "creating .venv and updating pip"
if [ ! -x $VPY ]; then
  say "creating .venv with $PY ($("$PY" -V 2>&1))"
  "$PY" -m venv .venv || die "$PY -m venv failed (Debian and Ubuntu: apt install python3-venv)"
fi
rm -f "$STATE"   # from here until the final check, .venv is being changed
: >"$LOG"
step "updating pip" $VPY -m pip install --upgrade pip setuptools wheel

if [ "$kind" = parallel ] && ! build_parallel; then
  [ "$STACK" = parallel ] && die "STACK=parallel: building against $STACK_MPICC and $STACK_HDF5 failed (see above and $LOG)"
  say "falling back to the wheel stack"
  kind=wheels
  STAGE=1
  STAGES=4
fi
[ "$kind" = wheels ] && install_wheels
install_project
stack_works "$kind" || die "the $kind stack does not import (.venv is left incomplete; rerun setup)"
echo "$kind" >"$STATE"
compile_kernels
report "$kind"
