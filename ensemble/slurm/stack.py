"""What the jobs' python has: the MPI its mpi4py was built against, and whether it imports this package."""
import os
import subprocess

# run by the jobs' python: the MPI library, the libmpi file mpi4py loaded (Linux), the mpich wheel if any
_STACK_PROBE = """
import importlib.metadata, os, mpi4py, ensemble, analysis, h5py
from ensemble import environment
try:
    importlib.metadata.version("mpich")
    wheel = "1"
except importlib.metadata.PackageNotFoundError:
    wheel = ""
print(environment.mpi_line().removeprefix("mpi: "))
try:
    with open("/proc/self/maps") as maps:
        paths = {line.split()[-1] for line in maps if "/" in line}
    print(" ".join(sorted(p for p in paths if os.path.basename(p).startswith("libmpi"))))
except OSError:
    print()
print(wheel)
"""


WHEEL_MPI = "the mpich wheel inside the environment"   # how python_stack names that MPI (the end of its text)


def python_stack(python):
    """(problem, mpi) for the jobs' `python`, started outside the repository as the jobs are:
    problem is None or a warning (not on this machine, cannot import what the jobs need); mpi
    describes the MPI its mpi4py was built against ("" when unknown)."""
    if not os.path.exists(python):
        return f"note: {python} is not on this machine; not checked that it has this package", ""
    res = subprocess.run([python, "-c", _STACK_PROBE], cwd="/", capture_output=True, text=True,
                         stdin=subprocess.DEVNULL, timeout=120)
    if res.returncode != 0:
        why = (res.stderr.strip().splitlines() or ["?"])[-1]
        return (f"warning: {python}, started outside the repository, cannot import what the jobs need "
                f"({why}); install the package into it (pip install -e .)"), ""
    library, files, wheel = (res.stdout.splitlines() + ["", "", ""])[:3]
    if wheel:
        return None, f"{library}, {WHEEL_MPI}"
    return None, f"{library}" + (f", {files}" if files else "")


def mpi_note(opt):
    """The command's line on the MPI the nodes need (opt.mpi from python_stack())."""
    if not opt.mpi:
        return ("note: the nodes need the MPI that mpi4py and h5py of the jobs' python were built against "
                "(load it with --setup 'module load ...')")
    if opt.mpi.endswith(WHEEL_MPI):
        hint = ("" if opt.launcher == "mpiexec"
                else "; start its ranks with --launcher mpiexec (docs/install.md: srun and PMI)")
        return f"note: MPI: {opt.mpi}; the nodes need no MPI of their own{hint}"
    return (f"note: the nodes need the MPI this environment was built against ({opt.mpi}): "
            f"the same MPI on every node, loaded in the jobs (--setup 'module load ...') where it is a module")
