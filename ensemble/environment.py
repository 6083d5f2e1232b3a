"""The software stack of a run: which MPI, which HDF5 (with MPI or not), which catalog writer.

Two stacks are common: the wheel stack (MPICH from its PyPI wheel, h5py without MPI: with more
than one rank, rank 0 writes for all) and the parallel stack (mpi4py and h5py built against the
machine's MPI and parallel HDF5: all ranks write one file through mpio). `validate` prints
describe(), a run's log starts with stack(), and each catalog stores software() as its
`software` attribute.
"""
import sys

import h5py
import mpi4py

from .store import writers


def mpi_line():
    """The MPI library (first line of its version text), the MPI standard and mpi4py."""
    # imported here, when asked: importing mpi4py.MPI initialises MPI (a singleton without mpiexec)
    from mpi4py import MPI
    first = (MPI.Get_library_version().strip().splitlines() or ["unknown MPI library"])[0]
    major, minor = MPI.Get_version()
    return f"mpi: {' '.join(first.split())} (MPI {major}.{minor}, mpi4py {mpi4py.__version__})"


def hdf5_line():
    """The HDF5 library h5py is built on, and whether that build has MPI (needed by the parallel writer)."""
    mpi = "with" if writers.has_parallel_hdf5() else "without"
    return f"hdf5: {h5py.version.hdf5_version} {mpi} MPI (h5py {h5py.__version__})"


def stack():
    """[mpi line, hdf5 line]."""
    return [mpi_line(), hdf5_line()]


def writer_line(name):
    """What output.writer = name gives on one rank and on more, in the run log's words.

    Raises ConfigError where the run would refuse the writer (writers.writer_key).
    """
    parallel = writers.has_parallel_hdf5()
    one, more = (writers.WRITERS[writers.writer_key(name, n, parallel)].label(n) for n in (1, 2))
    if name == "auto" and not parallel:
        more += " (h5py has no MPI)"
    if one == more:
        return f"writer: {name} -> any number of ranks: {one}"
    return f"writer: {name} -> 1 rank: {one}; more ranks: {more}"


def describe(name):
    """validate's lines: the stack and what output.writer = name resolves to."""
    return [*stack(), writer_line(name)]


def software(writer, n_ranks):
    """The text stored in a catalog: the stack, python, numpy, numba, and the writer class used on n_ranks."""
    import numba
    import numpy
    python = ".".join(map(str, sys.version_info[:3]))
    return "\n".join([*stack(), f"python {python}, numpy {numpy.__version__}, numba {numba.__version__}",
                      f"writer ({n_ranks} rank{'s' if n_ranks > 1 else ''}): {writer.label(n_ranks)}"])
