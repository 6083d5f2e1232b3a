#!/usr/bin/env bash
# The quick start as a new user meets it: not root, a fresh clone, the system's Python, no MPI on
# PATH. Runs the README's run command (`make run`: setup falls back to the wheel stack), then the
# same config on 2 ranks with the environment activated (`mpirun -n 2 python -m ensemble run ...`,
# the mpich wheel's mpirun, the rank-0 writer), checks that the two catalogs hold the same events,
# and runs tests/test_mpi.py on that stack. Prints how long each step took.
#
#   bash tests/install_wheels.sh [USER]      # as root (it creates USER, default ensemble-user)
#
# "No MPI on PATH": the user's PATH is one directory of links to /usr/bin's programs, less every
# MPI and parallel-HDF5 wrapper (mpicc, mpiexec, h5pcc, ...), whatever this machine has installed.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
USER_NAME=${1:-ensemble-user}
say() { echo "install_wheels: $*"; }
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
  case ${f##*/} in mpi*|*mpich*|hydra*|h5p*|ompi*|orte*) continue ;; esac
  ln -s "$f" "$bin/"
done
git clone -q "$ROOT" "$work/repo"
chown -R "$USER_NAME": "$work"

as_user() {
  runuser -u "$USER_NAME" -- env -i HOME="$home" PATH="$bin" LANG=C.UTF-8 CI="${CI:-}" bash -c "$1"
}
as_user "cd '$work/repo' && set -euo pipefail
  ! command -v mpicc && ! command -v mpiexec && ! command -v h5pcc
  now() { date +%s.%N; }
  since() { python3 -c \"import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.0f} s')\" \"\$1\" \"\$(now)\"; }
  t0=\$(now)
  make setup 2>&1 | tee setup.log
  grep -q 'falling back to the wheel stack' setup.log
  test \"\$(cat .venv/ensemble-stack)\" = wheels
  echo \"install_wheels: setup (wheel stack, from a fresh clone): \$(since \$t0)\"
  t1=\$(now)
  make run 2>&1 | tee run.log
  echo \"install_wheels: the serial run (make run, numba compiling the kernel first): \$(since \$t1)\"
  echo \"install_wheels: fresh clone to the end of make run: \$(since \$t0)\"
  . .venv/bin/activate
  test \"\$(command -v mpirun)\" = \"\$PWD/.venv/bin/mpirun\"
  t2=\$(now)
  mpirun -n 2 python -m ensemble run examples/small.toml -o small2.h5 2>&1 | tee run2.log
  echo \"install_wheels: the 2-rank run: \$(since \$t2)\"
  grep -q 'with 2 rank(s): serial HDF5 on rank 0' run2.log
  python -m tests.same_catalogs small.h5 small2.h5
  python -m ensemble validate examples/small.toml | grep '^# \\(mpi\\|hdf5\\|writer\\)'
  ENSEMBLE_TEST_STACK=wheels NUMBA_CACHE_DIR=\$PWD/.numba_cache OMP_NUM_THREADS=1 \
    python -m pytest -q -rs tests/test_mpi.py
"
rm -rf "$work"
say "ok"
