"""What a file is, in words, so that a wrong argument gets a one-line answer, not a traceback.

The commands take three kinds of files: run configs (TOML), event catalogs (HDF5 whose root
attribute `format` starts with "bk-catalog-", ensemble/store/) and reduction summaries (HDF5,
`format` "bk-summary-N", analysis/summary.py). A catalog and its summary sit side by side, both
*.h5, so giving one for the other is an easy slip; `require` says what was given and what to give:

    my.summary.h5 is a reduction summary (HDF5, reduced from my.h5), not an event catalog (give the catalog it
    was reduced from)

Exit codes (README table) follow the role of the argument, not what was found in its place:
where a config is expected, anything else is a bad config (ConfigError, exit 2, as a missing
config always was); where a catalog or a summary is expected, anything else - missing, a
directory, the other kind, a config, a damaged file - is a file error (CatalogError or
SummaryError, exit 1, as a missing catalog always was). Exit 2 stays for bad options.
"""
import os
import stat
from contextlib import contextmanager

from .sections import POPULATION, SECTION_NAMES, SWEEP

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
CATALOG_FORMAT_PREFIX = "bk-catalog-"
SUMMARY_FORMAT_PREFIX = "bk-summary-"
TOML_SIZE_LIMIT = 1 << 20   # bytes: configs are a few kB (a sweep of 10^4 values ~100 kB)

# kind -> what the path is, as the predicate of "PATH ..."
KINDS = {
    "missing": "does not exist",
    "directory": "is a directory",
    "unreadable": "cannot be read",
    "special": "is not a regular file",
    "empty": "is an empty file",
    "catalog": "is an event catalog (HDF5)",
    "summary": "is a reduction summary (HDF5)",
    "hdf5": "is an HDF5 file but neither an event catalog nor a reduction summary",
    "damaged": "is a damaged or truncated HDF5 file",
    "config": "is a run config (TOML)",
    "toml": "is a TOML file but not a run config",
    "other": "is neither an HDF5 file nor TOML",
}
NOUNS = {"catalog": "an event catalog", "summary": "a reduction summary", "config": "a TOML config"}
# (found, wanted) -> what to do instead
HINTS = {
    ("summary", "catalog"): "give the catalog it was reduced from",
    ("catalog", "summary"): "reduce it first: python -m analysis reduce {path}",
    ("config", "catalog"): "run it first: python -m ensemble run {path}",
    ("config", "summary"): "run it and reduce the catalog first",
    ("catalog", "config"): "its config is in it: python -m ensemble status {path}",
}


class FileKindError(RuntimeError):
    """A file of the wrong kind (callers usually pass their own error class to `require`)."""


def one_line(err):
    """An exception's message on one line (HDF5's messages can span several)."""
    return " ".join(str(err).split()) or type(err).__name__


def identify(path):
    """(kind, detail): kind a key of KINDS; detail a few words more, or ""."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "missing", ""
    except OSError as err:
        return "unreadable", err.strerror or one_line(err)
    if stat.S_ISDIR(mode):
        return "directory", ""
    if not stat.S_ISREG(mode):   # never open a FIFO or device just to look at it
        return "special", ""
    try:
        with open(path, "rb") as fh:
            head = fh.read(TOML_SIZE_LIMIT + 1)
            hdf5 = _has_hdf5_signature(fh, head)
    except OSError as err:
        return "unreadable", err.strerror or one_line(err)
    if not head:
        return "empty", ""
    if hdf5:
        return _hdf5_kind(path)
    return _text_kind(head)


def _has_hdf5_signature(fh, head):
    # the superblock sits at offset 0 or, after a user block, at 512, 1024, 2048, ...
    offset = 0
    while True:
        if offset + 8 <= len(head):
            found = head[offset:offset + 8]
        else:
            fh.seek(offset)
            found = fh.read(8)
            if len(found) < 8:
                return False
        if found == HDF5_SIGNATURE:
            return True
        offset = 512 if offset == 0 else 2 * offset


def _hdf5_kind(path):
    import h5py
    try:
        with h5py.File(path, "r", locking=False) as h5:
            attrs = {k: h5.attrs[k] for k in ("format", "catalog", "mu_c") if k in h5.attrs}
            groups = set(h5)
    except Exception as err:  # noqa: BLE001 - HDF5 raises OSError, KeyError, RuntimeError ... here
        return "damaged", one_line(err)
    fmt = attrs.get("format")
    fmt = fmt.decode(errors="replace") if isinstance(fmt, bytes) else fmt
    if isinstance(fmt, str) and fmt.startswith(CATALOG_FORMAT_PREFIX):
        return "catalog", ""
    # summaries written before they carried a format attribute are known by their contents
    if (isinstance(fmt, str) and fmt.startswith(SUMMARY_FORMAT_PREFIX)) or (
            {"catalog", "mu_c"} <= set(attrs) and {"points", "per_task"} <= groups):
        source = attrs.get("catalog")
        return "summary", f"reduced from {source}" if source is not None else ""
    return "hdf5", f"format {fmt!r}" if fmt is not None else ""


def _text_kind(head):
    import tomllib
    if len(head) > TOML_SIZE_LIMIT or b"\0" in head:
        return "other", ""
    try:
        doc = tomllib.loads(head.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        return "other", ""
    if doc and set(doc) <= {*SECTION_NAMES, SWEEP, POPULATION}:
        return "config", ""
    return "toml", ""


def describe(path, found=None):
    """What `path` is, as the predicate of "PATH ...", e.g. "is a directory" (found: its identify(), if known)."""
    kind, detail = identify(path) if found is None else found
    words = KINDS[kind]
    if not detail:
        return words
    if words.endswith(")"):
        return f"{words[:-1]}, {detail})"
    return f"{words} ({detail})"


def require(path, wanted, error=FileKindError, found=None):
    """Raise error(one line) unless `path` is of kind `wanted` ("catalog", "summary" or "config").

    found: identify(path) where the caller has it already (the file is looked at once).
    """
    found = identify(path) if found is None else found
    kind = found[0]
    if kind == wanted:
        return
    if kind == "missing":
        message = f"{path} does not exist"
        if wanted == "catalog" and os.path.exists(str(path) + ".partial"):
            message += (f" ({path}.partial does: a run that has not finished; continue it with "
                        f"`python -m ensemble resume {path}`)")
    elif kind in ("unreadable", "damaged"):
        message = f"{path} {describe(path, found)}"
    else:
        message = f"{path} {describe(path, found)}, not {NOUNS[wanted]}"
        hint = HINTS.get((kind, wanted))
        if hint:
            message += f" ({hint.format(path=path)})"
    raise error(message)


@contextmanager
def reading(path, noun, error):
    """Inside, what HDF5 raises on a damaged file becomes error("PATH: cannot read NOUN ...").

    A file that opens can still fail later, on any object whose bytes are damaged; h5py then
    raises OSError, KeyError, RuntimeError or ValueError, and a corrupt size can make numpy
    ask for more memory than exists (MemoryError). Errors of class `error` pass unchanged.
    """
    try:
        yield
    except error:
        raise
    except (OSError, KeyError, RuntimeError, ValueError, MemoryError) as err:
        raise error(f"{path}: cannot read {noun}, damaged or truncated? "
                    f"({type(err).__name__}: {one_line(err)})") from err
