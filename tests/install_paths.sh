#!/usr/bin/env bash
# The install paths as a new user meets them: not root (so setup cannot apt-get), a fresh clone,
# the system's Python, a PATH that shows only what the case puts there.
#
#   bash tests/install_paths.sh wheels    # no MPI on the machine: `make run` falls back to wheels
#   bash tests/install_paths.sh found     # an MPI and a parallel HDF5 as `module load` gives them:
#                                         # `make setup` still takes the wheels, naming the stack found
#   bash tests/install_paths.sh modules   # the same machine, STACK=parallel: built against them
#
# Run as root (it creates the user ensemble-user); CI runs both (.ci/run). SHARED_NUMBA_CACHE=DIR (CI sets
# it) gives every case the one kernel cache DIR (made writable for the user): the clones are of one commit,
# so the first case's `make setup` compiles the kernels and the others' load them. Each case sets up
# (`wheels`: `make setup`, the default a new .venv gets; `modules`: `make setup STACK=parallel`),
# runs the README's run command (`make run`), the Quick start's first run (which must compile
# nothing: one numba cache), then the same config on 2 ranks with the environment activated
# (`mpirun -n 2 python -m ensemble run ...`), checks the writer each used and that the catalogs
# hold the same events, and prints how long each step took (the README's and docs/install.md's
# setup times). `wheels` also runs part of tests/test_mpi.py on its stack.
#
# The user's PATH is one directory of links to /usr/bin's programs less every MPI and HDF5 wrapper
# (mpicc, mpiexec, h5pcc, ...) and pkg-config, whatever this machine has installed. `modules` adds
# a directory as an MPI module would (mpicc, mpiexec, mpirun of Debian's MPICH) and sets HDF5_DIR to
# Debian's parallel HDF5 prefix, as an HDF5 module does; it needs those packages (`make test` as
# root installs them).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CASE=${1:?usage: bash tests/install_paths.sh wheels|found|modules}
USER_NAME=ensemble-user
say() { echo "install_paths $CASE: $*"; }
[ "$(id -u)" = 0 ] || { say "run this as root: it creates the user $USER_NAME" >&2; exit 2; }

PY=/usr/bin/python3
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' || { say "$PY is older than 3.11" >&2; exit 2; }
if ! "$PY" -c "import ensurepip" 2>/dev/null; then   # a machine's Python, as a user finds it installed
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null
fi
id -u "$USER_NAME" >/dev/null 2>&1 || useradd -m -s /bin/bash "$USER_NAME"
home=$(getent passwd "$USER_NAME" | cut -d: -f6)
work=$(mktemp -d "$home/install-XXXX")
bin=$work/bin
mkdir "$bin"
for f in /usr/bin/*; do
  case ${f##*/} in mpi*|*mpich*|hydra*|h5*|ompi*|orte*|pkg-config|*-pkg-config|pkgconf) continue ;; esac
  ln -s "$f" "$bin/"
done
path=$bin
module=""
extra=()
case $CASE in
  wheels)
    expect_stack=wheels
    expect_writer="serial HDF5 on rank 0"
    stack_arg=
    # the wheel stack's MPI and its rank-0 writer: the same catalog on 1 and 2 ranks, a signal to the rank that
    # does not write, kill -9, an error on one rank (`make test` runs the rest on the parallel stack, rank0 too)
    tests="ENSEMBLE_TEST_STACK=wheels OMP_NUM_THREADS=1 python -m pytest -q -rs tests/test_mpi.py -k 'writer[1-auto] or writer[3-rank0] or uninterrupted[15-other-rank0] or kill9 or genuine_error'"
    ;;
  modules|found)
    hdf5=/usr/lib/x86_64-linux-gnu/hdf5/mpich
    [ -x /usr/bin/mpicc.mpich ] && [ -r "$hdf5/include/H5pubconf.h" ] \
      || { say "needs Debian's mpich, libmpich-dev and libhdf5-mpich-dev" >&2; exit 2; }
    module=$work/modules/mpich/bin
    mkdir -p "$module"
    for f in mpicc mpiexec mpirun; do ln -s "/usr/bin/$f.mpich" "$module/$f"; done
    for f in /usr/bin/hydra_*; do ln -s "$f" "$module/"; done
    path=$module:$bin
    extra=(HDF5_DIR="$hdf5")
    expect_stack=parallel
    stack_arg=STACK=parallel
    expect_writer="parallel HDF5 (mpio)"
    tests=true
    if [ "$CASE" = found ]; then
      expect_stack=wheels
      stack_arg=
      expect_writer="serial HDF5 on rank 0"
    fi
    ;;
  *) say "unknown case (wheels, found or modules)" >&2; exit 2 ;;
esac
git clone -q "$ROOT" "$work/repo"
chown -R "$USER_NAME": "$work"
if [ -n "${SHARED_NUMBA_CACHE:-}" ]; then
  mkdir -p "$SHARED_NUMBA_CACHE" && chmod 1777 "$SHARED_NUMBA_CACHE"
  extra+=(NUMBA_CACHE_DIR="$SHARED_NUMBA_CACHE")
fi

# a pip cache of its own: every run downloads (and builds) as on a new account, so the times it prints
# are those of a fresh machine however often it runs here
runuser -u "$USER_NAME" -- env -i HOME="$home" PATH="$path" LANG=C.UTF-8 PIP_CACHE_DIR="$work/pip-cache" \
  "${extra[@]}" bash -c "
  set -euo pipefail
  cd '$work/repo'
  say() { echo 'install_paths $CASE:' \"\$@\"; }
  now() { date +%s.%N; }
  since() { python3 -c \"import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.0f} s')\" \"\$1\" \"\$(now)\"; }
  absent() { for c in \"\$@\"; do if command -v \$c; then say \"\$c is on PATH\"; exit 1; fi; done; }
  absent pkg-config h5pcc
  [ $CASE = wheels ] && absent mpicc mpiexec mpirun
  t0=\$(now)
  make setup $stack_arg 2>&1 | tee setup.log
  test \"\$(cat .venv/ensemble-stack)\" = $expect_stack
  [ $CASE = wheels ] && grep -q 'falling back to the wheel stack' setup.log
  [ $CASE = found ] && grep -q 'a parallel HDF5 stack is on this machine ($module/mpicc, HDF5_DIR=' setup.log
  [ $CASE = modules ] && grep -q 'building mpi4py against $module/mpicc' setup.log
  [ $CASE = modules ] && grep -q 'building h5py against HDF5_DIR=' setup.log
  say \"setup from a fresh clone: \$(since \$t0)\"
  # found: the stack set up is the wheel stack, so make run and the runs after it are the wheels case's
  [ $CASE = found ] && { say 'the wheel stack, as make run takes it: its runs are those of the wheels case'; exit 0; }
  t1=\$(now)
  make run 2>&1 | tee run.log
  say \"the serial run (make run; the kernels compiled by make setup): \$(since \$t1)\"
  say \"fresh clone to the end of make run: \$(since \$t0)\"
  t3=\$(now)
  .venv/bin/python -m ensemble run examples/small.toml -o my.h5 2>&1 | tee quick.log
  if grep -q 'compiling kernels' quick.log; then say 'the Quick start run compiled the kernels again'; exit 1; fi
  say \"the Quick start's run after make run (no compiling): \$(since \$t3)\"
  . .venv/bin/activate
  [ $CASE = modules ] || test \"\$(command -v mpirun)\" = \"\$PWD/.venv/bin/mpirun\"
  t2=\$(now)
  mpirun -n 2 python -m ensemble run examples/small.toml -o small2.h5 2>&1 | tee run2.log
  say \"the 2-rank run: \$(since \$t2)\"
  grep -q 'with 2 rank(s): $expect_writer' run2.log
  python -m tests.same_catalogs small.h5 small2.h5
  python -m ensemble validate examples/small.toml | grep '^# \\(mpi\\|hdf5\\|writer\\)'
  $tests
"
rm -rf "$work"
say "ok"
