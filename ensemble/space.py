"""Disk space and the file-size limit, checked before HDF5 touches a file.

HDF5 meets a full disk or `ulimit -f` in the middle of a write: serially the file is left half
made (and closing it may crash the process), under MPI one rank fails inside a collective call that
the others wait in forever. So a run first proves, with plain files, that its catalog fits: the
file-size limit (RLIMIT_FSIZE) is compared with the catalog's size, and that many bytes are
reserved (fallocate) in a scratch file beside the catalog and freed again. Only then is the catalog
made (and its own blocks reserved, store/files.py: reserve_space). A resume reserves the blocks of the
file it continues, which a run on a file system without fallocate never reserved.

Every other file the project writes (summaries, figures, export tables, comparisons, Slurm jobs) is written by
write_file: never through a link, its blocks reserved first (tests/test_writes.py holds every command to it).
"""
import ctypes
import errno
import os
import resource

MiB = 2 ** 20


class NoSpace(OSError):
    """The catalog does not fit: its message says how much it needs and what stops it."""


def _fallocate():
    libc = ctypes.CDLL(None, use_errno=True)
    fn = getattr(libc, "fallocate", None)
    if fn is not None:
        fn.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64)
    return fn


def size_limit():
    """The process's file-size limit in bytes (ulimit -f), or None if there is none."""
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return None if soft == resource.RLIM_INFINITY else soft


def reserve(fd, nbytes, what):
    """Allocate the first nbytes of the open file `fd` now; NoSpace if the disk or a quota cannot
    hold them. False where the file system cannot reserve (nothing was checked), else True."""
    fallocate = _fallocate()
    if fallocate is None or nbytes <= 0:
        return False
    if fallocate(fd, 0, 0, nbytes) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
        raise NoSpace(err, f"{os.strerror(err)}: {what} needs {nbytes / MiB:.1f} MiB")
    return False       # EOPNOTSUPP and the like: this file system does not reserve


def check_fits(path, nbytes):
    """Raise NoSpace unless a file of nbytes can be written at `path` (which is not touched):
    the file-size limit, then the space itself, reserved in a scratch file beside it and freed."""
    limit = size_limit()
    if limit is not None and nbytes > limit:
        raise NoSpace(errno.EFBIG, f"File too large: the catalog needs {nbytes / MiB:.1f} MiB and the "
                                   f"file-size limit (ulimit -f) is {limit / MiB:.1f} MiB")
    scratch = f"{path}.space-{os.getpid()}"
    fd = os.open(scratch, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        if not reserve(fd, nbytes, "the catalog"):
            stat = os.statvfs(os.path.dirname(os.path.abspath(path)))
            free = stat.f_bavail * stat.f_frsize
            if free < nbytes:
                raise NoSpace(errno.ENOSPC, f"No space left on device: the catalog needs {nbytes / MiB:.1f} MiB, "
                                            f"{free / MiB:.1f} MiB are free")
    finally:
        os.close(fd)
        os.remove(scratch)


def reserve_file(path):
    """Reserve the blocks of an existing file (a resume's catalog); NoSpace if they do not fit."""
    size = os.path.getsize(path)
    limit = size_limit()
    if limit is not None and size > limit:
        raise NoSpace(errno.EFBIG, f"File too large: the catalog is {size / MiB:.1f} MiB and the file-size "
                                   f"limit (ulimit -f) is {limit / MiB:.1f} MiB")
    fd = os.open(path, os.O_RDWR)
    try:
        reserve(fd, size, "the catalog")
    finally:
        os.close(fd)


def write_file(path, data, what):
    """Write `data` to `path` (made or replaced), the one way the project writes a file that is not a catalog or
    its lock (summaries, figures, export tables, comparisons, Slurm jobs): never through a symbolic link at
    `path` (its target would be written: O_NOFOLLOW, ELOOP), with plain file I/O, the blocks reserved first where
    the size is known. `data`: bytes or text (UTF-8), or an iterable of them written in turn (a large table,
    streamed: nothing to reserve ahead, and a write that fails is an OSError like any other). A full disk, a
    quota or `ulimit -f` is an OSError naming `what` (NoSpace where it does not fit), and `path` is removed. HDF5
    files are built in memory first and written here (an HDF5 write that fails on a full disk leaves a file that
    may crash the process when closed)."""
    if isinstance(data, str):
        data = data.encode()
    whole = isinstance(data, (bytes, bytearray, memoryview))
    parts = [data] if whole else data
    size = memoryview(data).nbytes if whole else None
    limit = size_limit()
    if size is not None and limit is not None and size > limit:
        raise NoSpace(errno.EFBIG, f"File too large: {what} needs {size / MiB:.1f} MiB and the file-size "
                                   f"limit (ulimit -f) is {limit / MiB:.1f} MiB")
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW | os.O_NONBLOCK, 0o644)
    try:
        if size is not None:
            reserve(fd, size, what)
        for part in parts:
            view = memoryview(part.encode() if isinstance(part, str) else part)
            while view:
                view = view[os.write(fd, view):]
        os.fsync(fd)
    except BaseException:
        os.close(fd)
        os.remove(path)
        raise
    os.close(fd)
