"""Find an MPI compiler and a parallel HDF5 already on this machine, for scripts/setup.sh.

Standard library only: it runs before the virtual environment exists. Prints shell assignments
for setup.sh to eval, for example

    STACK_FOUND=1
    STACK_MPICC=/usr/bin/mpicc
    STACK_HDF5='pkg-config hdf5-mpich (/usr/include/hdf5/mpich)'
    STACK_H5PY_ENV='HDF5_PKGCONFIG_NAME=hdf5-mpich'

or STACK_FOUND=0 with STACK_MISSING saying what is missing. Where it looks, in this order:

- MPI compiler: $MPICC, else `mpicc` on PATH; not a virtual environment's own (the `mpich`
  wheel puts an mpicc into .venv/bin that has no parallel HDF5 beside it).
- parallel HDF5: $HDF5_DIR or $HDF5_ROOT (set by module systems and `spack load`), then h5pcc on
  PATH (its `-showconfig`), then pkg-config (hdf5-mpich, hdf5-openmpi, hdf5). A candidate is
  parallel when its H5pubconf.h defines H5_HAVE_PARALLEL.

    python3 scripts/stack.py            # the assignments
    python3 scripts/stack.py --explain  # the same, with every place looked at
    mpiexec -n 2 .venv/bin/python scripts/stack.py --check-mpio DIR   # the built stack writes in parallel
"""
import os
import re
import shlex
import shutil
import subprocess
import sys

PKGCONFIG_NAMES = ("hdf5-mpich", "hdf5-openmpi", "hdf5")
PARALLEL_DEFINE = re.compile(r"^\s*#\s*define\s+H5_HAVE_PARALLEL\s+1", re.M)


def _output(argv, env):
    try:
        res = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return res.stdout if res.returncode == 0 else None


def _in_venv(path):
    """True for an executable in a virtual environment's bin/ (pyvenv.cfg beside bin/)."""
    root = os.path.dirname(os.path.dirname(os.path.realpath(path)))
    return os.path.exists(os.path.join(root, "pyvenv.cfg"))


def find_mpicc(env, notes):
    """Path of the MPI C compiler to build against, or None."""
    if env.get("MPICC"):
        path = shutil.which(env["MPICC"], path=env.get("PATH"))
        notes.append(f"MPICC={env['MPICC']}: " + ("found" if path else "not an executable"))
        return path
    for d in env.get("PATH", "").split(os.pathsep):
        path = shutil.which("mpicc", path=d) if d else None
        if path is None:
            continue
        if _in_venv(path):
            notes.append(f"{path}: a virtual environment's own (the mpich wheel), not used")
            continue
        notes.append(f"{path}: found")
        return path
    notes.append("mpicc: not on PATH and MPICC unset")
    return None


def _header_parallel(include_dirs):
    """(H5pubconf.h found, it defines H5_HAVE_PARALLEL) for the first of include_dirs that has one."""
    for d in include_dirs:
        header = os.path.join(d, "H5pubconf.h")
        if os.path.isfile(header):
            with open(header, errors="replace") as f:
                return header, bool(PARALLEL_DEFINE.search(f.read()))
    return None, False


def _from_prefix(where, prefix, notes):
    """An HDF5 installed under prefix (include/, lib/), as h5py's HDF5_DIR takes it."""
    header, parallel = _header_parallel([os.path.join(prefix, "include")])
    if header is None:
        notes.append(f"{where}: no {prefix}/include/H5pubconf.h")
        return None
    notes.append(f"{where}: " + ("parallel" if parallel else "serial (no H5_HAVE_PARALLEL)"))
    return (where, f"HDF5_DIR={prefix}") if parallel else None


def _from_h5pcc(env, notes):
    h5pcc = shutil.which("h5pcc", path=env.get("PATH"))
    if h5pcc is None:
        notes.append("h5pcc: not on PATH")
        return None
    text = _output([h5pcc, "-showconfig"], env) or ""
    prefix = re.search(r"Installation point:\s*(\S+)", text)
    parallel = re.search(r"Parallel HDF5:\s*yes", text)
    if not (prefix and parallel):
        notes.append(f"{h5pcc}: -showconfig does not say 'Parallel HDF5: yes' with an installation point")
        return None
    # Debian's h5pcc names /usr, its headers are under include/hdf5/<mpi>: then pkg-config knows better
    return _from_prefix(f"{h5pcc} (installation point {prefix.group(1)})", prefix.group(1), notes)


def _from_pkgconfig(env, notes):
    if shutil.which("pkg-config", path=env.get("PATH")) is None:
        notes.append("pkg-config: not on PATH")
        return None
    for name in PKGCONFIG_NAMES:
        flags = _output(["pkg-config", "--cflags-only-I", name], env)
        if flags is None:
            notes.append(f"pkg-config {name}: not known")
            continue
        dirs = [f[2:] for f in flags.split() if f.startswith("-I")]
        if not dirs:
            dirs = [d for d in [_output(["pkg-config", "--variable=includedir", name], env)] if d]
            dirs = [d.strip() for d in dirs]
        header, parallel = _header_parallel(dirs)
        if not parallel:
            notes.append(f"pkg-config {name}: " + ("serial (no H5_HAVE_PARALLEL)" if header else "no H5pubconf.h"))
            continue
        notes.append(f"pkg-config {name}: parallel")
        return f"pkg-config {name} ({os.path.dirname(header)})", f"HDF5_PKGCONFIG_NAME={name}"
    return None


def find_parallel_hdf5(env, notes):
    """(description, h5py build variable) of the first parallel HDF5 found, or None."""
    for var in ("HDF5_DIR", "HDF5_ROOT"):
        if env.get(var):
            found = _from_prefix(f"{var}={env[var]}", env[var], notes)
            if found:
                return found
    return _from_h5pcc(env, notes) or _from_pkgconfig(env, notes)


def detect(env=None):
    """(assignments dict, notes list)."""
    env = dict(os.environ if env is None else env)
    notes = []
    mpicc = find_mpicc(env, notes)
    hdf5 = find_parallel_hdf5(env, notes)
    missing = []
    if mpicc is None:
        missing.append("an MPI C compiler (mpicc on PATH, or MPICC)")
    if hdf5 is None:
        missing.append("a parallel HDF5 (HDF5_DIR, h5pcc or pkg-config hdf5-mpich/hdf5-openmpi)")
    out = {"STACK_FOUND": "0" if missing else "1", "STACK_MISSING": " and ".join(missing),
           "STACK_MPICC": mpicc or "", "STACK_HDF5": hdf5[0] if hdf5 else "",
           "STACK_H5PY_ENV": hdf5[1] if hdf5 else ""}
    return out, notes


def check_mpio(directory):
    """Every rank writes its own element of one dataset through mpio; rank 0 reads them back."""
    import h5py
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    path = os.path.join(directory, "mpio-check.h5")
    with h5py.File(path, "w", driver="mpio", comm=comm) as f:
        data = f.create_dataset("rank", (comm.size,), dtype="i8")
        data[comm.rank] = comm.rank
    comm.Barrier()
    if comm.rank == 0:
        with h5py.File(path, "r") as f:
            got = list(f["rank"][:])
        os.remove(path)
        if got != list(range(comm.size)):
            raise SystemExit(f"mpio check: the ranks wrote {got}, expected {list(range(comm.size))}")
        library = " ".join(MPI.Get_library_version().splitlines()[0].split())
        print(f"mpio check: {comm.size} ranks wrote one file through MPI-IO ({library})")


def main(argv):
    if argv[:1] == ["--check-mpio"]:
        check_mpio(argv[1])
        return 0
    out, notes = detect()
    if "--explain" in argv:
        for line in notes:
            print(f"# {line}")
    for key, value in out.items():
        print(f"{key}={shlex.quote(value)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
