"""A catalog file's name while a run writes it, and its opening and creation (serial or mpio).

Opening checks what the file is once: a catalog opens and its `format` is read; anything else (missing,
a directory, a summary, a config, a damaged file) is worded by filekind.py, which is asked only then.
"""
import os
import stat

import h5py

from .. import filekind, space
from . import create
from .errors import CatalogError, reason
from .schema import FORMAT, OLDER, READABLE


def partial_path(path):
    """Where a run writes until every task has finished (then renamed to `path`)."""
    return str(path) + ".partial"


def check_format(h5, path, writing=False):
    """Close h5 and raise CatalogError unless its format is this version's (writing) or one it reads."""
    found = h5.attrs.get("format")
    if found == FORMAT or (found in READABLE and not writing):
        return
    h5.close()
    if found in OLDER:
        raise CatalogError(f"{path}: catalog format {found}, {OLDER[found]}: this version reads it but does not "
                           f"continue it (finish it with the older version, or rerun)")
    if isinstance(found, str) and found.startswith("bk-catalog-"):
        raise CatalogError(f"{path}: catalog format {found}, this version reads {', '.join(sorted(READABLE))} "
                           "(the checkpoint layout changed; rerun, or read it with the older version)")
    raise CatalogError(f"{path}: not an event catalog of this package")


def open_for_reading(path):
    """Open read-only without HDF5's file lock: a catalog may be read while a run writes it.

    That is safe because a catalog's metadata is complete and flushed at creation and
    never changes afterwards; what a run is writing lies beyond the commit rows read here.
    A file that is not a catalog is refused in filekind's words (filekind.require).
    """
    h5, failure = _try_open(path)
    if h5 is None or not _catalog_format(h5):
        if h5 is not None:
            h5.close()
        filekind.require(path, "catalog", CatalogError)     # says what the file is instead
        if h5 is None:      # (changed since: a catalog now)
            raise CatalogError(f"{path}: cannot read catalog ({failure})") from None
        raise CatalogError(f"{path}: not an event catalog of this package")
    check_format(h5, path)
    return h5


def _try_open(path):
    """(h5, None), or (None, the error) where the path is no regular file or HDF5 cannot open it
    (a FIFO or device is never opened: it could block)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None, None
        return h5py.File(path, "r", locking=False), None
    except OSError as err:
        return None, err


def _catalog_format(h5):
    try:
        found = h5.attrs.get("format")
    except Exception:  # noqa: BLE001 - a damaged file: filekind words it
        return False
    return isinstance(found, str) and found.startswith(filekind.CATALOG_FORMAT_PREFIX)


def open_for_writing(path, open_file):
    """Open an existing catalog to continue it (open_file: h5py.File, or an mpio opener)."""
    try:
        h5 = open_file(path, "r+")
    except OSError as err:
        raise CatalogError(f"{path}: cannot open catalog ({err})") from None
    check_format(h5, path, writing=True)
    return h5


# files whose HDF5 write failed: kept referenced until the process ends (os._exit, or MPI_Abort), as
# freeing one makes h5py close it, which fails again (a traceback per object) or crashes
BROKEN = []


def create_file(path, open_file, cfg, tasks, integrator_text, software):
    """Create a catalog's layout and flush it; on failure remove the file (we hold the run's lock) and raise
    CatalogError.

    A failed HDF5 write leaves the open file in a state where anything more, closing included, may
    crash HDF5 or (under mpio) wait for ranks that are elsewhere: then the file is removed, not closed,
    and the error is `broken` (the process ends at once; under MPI all ranks abort). space.check_fits
    has made that rare: it runs before, with plain files.
    """
    try:
        h5 = open_file(path, "w")
    except (OSError, ValueError, RuntimeError) as err:
        raise CatalogError(f"{path}: cannot create catalog ({reason(err)})") from None
    try:
        create.create_layout(h5, cfg, tasks, integrator_text, software)
        h5.flush()
        return h5
    except (OSError, ValueError, RuntimeError) as err:
        BROKEN.append(h5)
        discard(path)
        raise CatalogError(f"{path}: cannot create catalog ({reason(err)})", broken=True) from None


def reserve_space(path):
    """Reserve the file's disk blocks now (space.py), so that a full disk stops a run at its start,
    not hours later; where the file system cannot reserve, a write that fails later ends the run
    with a clear error instead."""
    fd = os.open(path, os.O_RDWR)
    try:
        space.reserve(fd, os.fstat(fd).st_size, "the catalog")
    finally:
        os.close(fd)


def discard(path):
    try:
        os.remove(path)
    except OSError:
        pass
