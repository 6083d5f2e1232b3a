"""Numba kernels of the Burridge-Knopoff chain with rate- and state-dependent friction.

Kernels are pure: arrays, scalars and the parameter record (params.py) in, arrays out. Nothing here knows about
config objects, files, MPI or HDF5 (see ensemble.runner for the wrapper).

Numba's on-disk cache only notices changes to the file of the cached function
itself, not to the kernels it calls from other files; a stale cache would run
old physics silently. The cache therefore lives in a directory named after a
hash of all kernel sources: $NUMBA_CACHE_DIR/bk-<hash> (default
~/.cache/bk-ensemble/numba/bk-<hash>).
"""
import hashlib
import os
from pathlib import Path

import numba


def _cache_dir():
    digest = hashlib.sha256()
    here = Path(__file__).parent
    for src in sorted(here.rglob("*.py")):
        digest.update(str(src.relative_to(here)).encode())
        digest.update(src.read_bytes())
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.path.expanduser("~"), ".cache", "bk-ensemble", "numba")
    return os.path.join(base, "bk-" + digest.hexdigest()[:16])


numba.config.CACHE_DIR = _cache_dir()
