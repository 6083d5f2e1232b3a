"""Where numba keeps the compiled kernels: one place for every entry point.

`make run`, `make test`, `python -m ensemble`, `python -m analysis`, the Slurm jobs and the tests
all take the cache from here, so the kernels are compiled once per checkout, not once per way of
starting them. The place, in order:

1. `$NUMBA_CACHE_DIR`, when set (a cluster's scratch disk, a test's empty cache);
2. `.numba_cache/` in the source checkout the package was imported from (the repository root:
   the editable install of scripts/setup.sh, or running from the tree), when it is writable;
3. `~/.cache/bk-ensemble/numba` otherwise (a package installed into a site-packages).

The kernels themselves live in a subdirectory named after a hash of their sources (directory()):
numba's own check notices a change only in the file of the cached function, not in the kernels it
calls from other files, so a stale cache would otherwise run old physics silently.

Inside it, numba would file each source directory's kernels under a hash of that directory's absolute
path, so two clones of one commit (CI's install paths, a checkout moved or copied to a cluster's nodes)
could not share a cache. relocatable() files them under the directory's path inside the package root
instead (`ensemble_model`): the bk-<hash> above already names the sources, and numba checks each file's
content (its stamp is a hash of the file in numba 0.62 and later), so a cache built in one clone serves
every clone of the same sources.
"""
import hashlib
import os
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]
USER_CACHE = Path("~/.cache/bk-ensemble/numba")


def base(environ=None):
    """The cache root every entry point uses (see the module docstring), as a string."""
    environ = os.environ if environ is None else environ
    if environ.get("NUMBA_CACHE_DIR"):
        return environ["NUMBA_CACHE_DIR"]
    if (CHECKOUT / "pyproject.toml").is_file() and os.access(CHECKOUT, os.W_OK):
        return str(CHECKOUT / ".numba_cache")
    return str(USER_CACHE.expanduser())


def relocatable():
    """Numba's cache locator for a given CACHE_DIR, filing kernels by their path under CHECKOUT (see the
    module docstring); installed once, first in numba's list. False where this numba has no such locator
    (its own then applies: one cache per clone)."""
    try:
        from numba.core import caching
        impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
        located = getattr(caching, "UserProvidedCacheLocator", None) or caching._UserProvidedCacheLocator
        classes = impl._locator_classes
    except (ImportError, AttributeError):
        return False
    if any(getattr(c, "checkout_relative", False) for c in classes):
        return True

    class CheckoutRelative(located):
        checkout_relative = True

        @classmethod
        def get_suitable_cache_subpath(cls, py_file):
            folder = Path(py_file).resolve().parent
            if not folder.is_relative_to(CHECKOUT):
                return super().get_suitable_cache_subpath(py_file)
            return "_".join(folder.relative_to(CHECKOUT).parts)

    classes.insert(0, CheckoutRelative)
    return True


def directory(sources, environ=None):
    """base()/bk-<hash of every .py file under `sources`>: the cache of the kernels defined there, filed by
    their path in the package (relocatable())."""
    relocatable()
    sources = Path(sources)
    digest = hashlib.sha256()
    for src in sorted(sources.rglob("*.py")):
        digest.update(str(src.relative_to(sources)).encode())
        digest.update(src.read_bytes())
    return os.path.join(base(environ), "bk-" + digest.hexdigest()[:16])
