"""Numba kernels of the Burridge-Knopoff chain with rate- and state-dependent friction.

Kernels are pure: arrays, scalars and the parameter record (params.py) in, arrays out. Nothing here knows about
config objects, files, MPI or HDF5 (see ensemble.run.trajectory for the wrapper).

Numba's on-disk cache only notices changes to the file of the cached function
itself, not to the kernels it calls from other files; a stale cache would run
old physics silently. The cache therefore lives in a directory named after a
hash of all kernel sources, under the one cache root of every entry point:
<root>/bk-<hash> (ensemble/kernel_cache.py: $NUMBA_CACHE_DIR, else the
checkout's .numba_cache, else ~/.cache/bk-ensemble/numba).
"""
from pathlib import Path

import numba

from .. import kernel_cache

numba.config.CACHE_DIR = kernel_cache.directory(Path(__file__).parent)
