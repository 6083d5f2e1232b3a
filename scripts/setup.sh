#!/usr/bin/env bash
# Idempotent setup of .venv in the repository root, with one of two stacks (docs/install.md):
#
#   parallel  mpi4py and h5py built against an MPI and a parallel HDF5 already on this machine
#             (modules, Spack, conda, Debian packages), found by scripts/stack.py. As root on Debian
#             with none found, MPICH and parallel HDF5 are installed from Debian first. Runs with
#             more than one rank write the catalog through MPI-IO (the parallel writer).
#   wheels    no root, no compiler, no MPI on the machine: MPICH from the `mpich` wheel, the mpi4py
#             and h5py wheels (h5py without MPI: runs with more ranks use the rank-0 writer).
#
# STACK=auto (default) takes parallel when it can, else says what is missing and installs wheels;
# STACK=parallel fails instead of falling back; STACK=wheels does not look. PYTHON picks the
# interpreter (default python3, >= 3.11). .venv/ensemble-stack names the stack once it is complete
# and checked; until then a rerun starts over, so an interrupted or failed setup leaves nothing
# that a run would use. A second run only checks (about a second).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
STACK=${STACK:-auto}
PY=${PYTHON:-python3}
VPY=.venv/bin/python
STATE=.venv/ensemble-stack
LOG=.venv/setup-build.log

say() { echo "setup: $*"; }
die() { echo "setup: error: $*" >&2; exit 1; }
quietly() {   # run "$@" with its output in $LOG, shown only if it fails
  "$@" >>"$LOG" 2>&1 || { say "failed: $*; the end of $LOG:"; tail -n 15 "$LOG" | sed 's/^/  /'; return 1; }
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
    say "installing the project (editable) with numpy, numba, matplotlib and the test tools"
    quietly $VPY -m pip install --only-binary=numpy,numba,llvmlite,matplotlib,scipy --no-build-isolation -e ".[test]"
    touch "$stamp"
  fi
}

report() {   # in validate's words (ensemble/environment.py): the MPI, the HDF5, the writer runs take
  echo "setup: ok: stack $1"
  $VPY -c "from ensemble import environment; print('\n'.join('  ' + line for line in environment.describe('auto')))"
}

# -- a complete stack already there: check and leave -----------------------------------------------
current=$(cat "$STATE" 2>/dev/null || true)
if [ -n "$current" ] && { [ "$STACK" = auto ] || [ "$STACK" = "$current" ]; } && stack_works "$current"; then
  install_project
  report "$current"
  exit 0
fi

build_parallel() {   # against $STACK_MPICC and $STACK_H5PY_ENV; output in $LOG
  say "building mpi4py against $STACK_MPICC and h5py against $STACK_HDF5 (a few minutes; log: $LOG)"
  {
    # the wheel's mpiexec and libmpi would shadow the MPI these are built against
    $VPY -m pip uninstall -q -y mpich 2>/dev/null || true
    MPICC=$STACK_MPICC $VPY -m pip install --no-binary=mpi4py --force-reinstall --no-deps mpi4py \
    && $VPY -m pip install numpy "Cython>=0.29.31" pkgconfig \
    && env CC="$STACK_MPICC" HDF5_MPI=ON "$STACK_H5PY_ENV" \
         $VPY -m pip install --no-binary=h5py --no-build-isolation --force-reinstall --no-deps h5py
  } >>"$LOG" 2>&1 || { say "the build failed; the end of $LOG:"; tail -n 15 "$LOG" | sed 's/^/  /'; return 1; }
  has_mpi_h5py || { say "h5py was built but has no MPI support"; return 1; }
  local mpiexec tmp
  mpiexec=$(dirname "$STACK_MPICC")/mpiexec
  [ -x "$mpiexec" ] || mpiexec=$(command -v mpiexec || true)
  if [ -z "$mpiexec" ]; then
    say "no mpiexec beside $STACK_MPICC or on PATH: the 2-rank MPI-IO check is left to the first run"
    return 0
  fi
  tmp=$(mktemp -d)
  if ! timeout 120 "$mpiexec" -n 2 $VPY scripts/stack.py --check-mpio "$tmp" >>"$LOG" 2>&1; then
    rm -rf "$tmp"
    say "the 2-rank MPI-IO check with $mpiexec failed; the end of $LOG:"
    tail -n 15 "$LOG" | sed 's/^/  /'
    return 1
  fi
  rm -rf "$tmp"
  say "$(tail -n 1 "$LOG")"
}

install_wheels() {
  say "installing the wheel stack: MPICH from the mpich wheel, mpi4py and h5py (without MPI) wheels"
  quietly $VPY -m pip install --only-binary=:all: --force-reinstall --no-deps "mpi4py>=4.1" mpich h5py
  quietly $VPY -m pip install --only-binary=:all: "mpi4py>=4.1" mpich h5py
}

# -- which stack: decided before .venv is touched, so that a refusal changes nothing ---------------
kind=wheels
if [ "$STACK" != wheels ]; then
  eval "$("$PY" scripts/stack.py)"
  if [ "$STACK_FOUND" = 0 ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 \
     && [ -r /etc/debian_version ]; then
    say "no parallel HDF5 stack found (missing $STACK_MISSING); as root on Debian: installing MPICH and parallel HDF5"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      mpich libmpich-dev libhdf5-mpich-dev pkg-config >/dev/null
    eval "$("$PY" scripts/stack.py)"
  fi
  if [ "$STACK_FOUND" = 1 ]; then
    kind=parallel
  else
    why="no parallel HDF5 stack: missing $STACK_MISSING"
    why="$why (python3 scripts/stack.py --explain shows where setup looked)"
    [ "$STACK" = parallel ] && die "STACK=parallel: $why. Load an MPI and a parallel HDF5 (module load ..., spack load ...; docs/install.md), or set STACK=wheels"
    say "$why"
    say "falling back to the wheel stack: runs work on any number of ranks, rank 0 writing the catalog"
  fi
fi

if [ ! -x $VPY ]; then
  say "creating .venv with $PY ($("$PY" -V 2>&1))"
  "$PY" -m venv .venv || die "$PY -m venv failed (Debian and Ubuntu: apt install python3-venv)"
fi
rm -f "$STATE"   # from here until the final check, .venv is being changed
: >"$LOG"
quietly $VPY -m pip install --upgrade pip setuptools wheel

if [ "$kind" = parallel ] && ! build_parallel; then
  [ "$STACK" = parallel ] && die "STACK=parallel: building against $STACK_MPICC and $STACK_HDF5 failed (see above and $LOG)"
  say "falling back to the wheel stack"
  kind=wheels
fi
[ "$kind" = wheels ] && install_wheels
install_project
stack_works "$kind" || die "the $kind stack does not import (.venv is left incomplete; rerun setup)"
echo "$kind" >"$STATE"
report "$kind"
