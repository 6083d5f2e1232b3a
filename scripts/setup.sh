#!/usr/bin/env bash
# Idempotent setup on Debian 12 as root: MPICH + parallel HDF5 from Debian,
# then a virtual environment at .venv with mpi4py and an MPI-enabled h5py built
# from source against them. A second run only checks and takes seconds.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
export DEBIAN_FRONTEND=noninteractive

need_pkgs=()
for p in mpich libmpich-dev libhdf5-mpich-dev pkg-config; do
  dpkg -s "$p" >/dev/null 2>&1 || need_pkgs+=("$p")
done
if [ ${#need_pkgs[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${need_pkgs[*]}"
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null
fi

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$PY" -m venv .venv
fi
VPY=.venv/bin/python

if ! $VPY -c "import mpi4py" 2>/dev/null; then
  echo "setup: building mpi4py against MPICH"
  $VPY -m pip install -q --upgrade pip setuptools wheel
  $VPY -m pip install -q --no-binary=mpi4py mpi4py
fi
if ! $VPY -c "import h5py, sys; sys.exit(0 if h5py.get_config().mpi else 1)" 2>/dev/null; then
  echo "setup: building h5py with parallel HDF5"
  $VPY -m pip install -q "numpy" "Cython>=0.29.31" pkgconfig setuptools wheel
  CC=mpicc HDF5_MPI=ON HDF5_PKGCONFIG_NAME=hdf5-mpich \
    $VPY -m pip install -q --no-binary=h5py --no-build-isolation --force-reinstall --no-deps h5py
fi
# The project itself (editable) with its remaining dependencies and test tools.
stamp=.venv/.ensemble-installed
# (an editable install maps the packages that existed when it ran: check from outside the tree)
if [ ! -f "$stamp" ] || [ setup.cfg -nt "$stamp" ] || [ pyproject.toml -nt "$stamp" ] \
   || ! (cd / && "$ROOT/$VPY" -c "import ensemble, analysis") 2>/dev/null; then
  echo "setup: installing the project"
  $VPY -m pip install -q --no-build-isolation -e ".[test]"
  touch "$stamp"
fi
$VPY -c "import h5py, mpi4py, numba; assert h5py.get_config().mpi; print('setup: ok (h5py', h5py.__version__, 'mpi, mpi4py', mpi4py.__version__, 'numba', numba.__version__ + ')')"
