"""The checks every command makes of its numeric options and its output paths: one place for each.

    checks.number("--mu-c", args.mu_c, lo=-20, hi=20)        # finite, in range, else UsageError naming it
    checks.count("--bootstrap", args.bootstrap, lo=1, hi=10**6)
    checks.output(path, inputs=[catalog], force=args.force)   # before any work
    checks.memory("--blocks x bins x tasks", n_bytes)          # an allocation this machine cannot hold
    checks.write_text(path, text, what="job script")           # a small text output, never through a link

Both raise UsageError (a ValueError): a one-line message naming the option or the path, exit code 2
in every command. An output is refused when its name is not UTF-8 (HDF5 and the lock need it), when
it is one of the command's inputs (also with --force), when it is a directory where a file goes (or
the reverse), when its directory is missing or not writable, and when it exists without --force.
"""
import errno
import math
import os

from . import space


class UsageError(ValueError):
    """A bad option or output path, found before any work (exit code 2)."""


def number(name, value, lo=-math.inf, hi=math.inf, exclusive=False):
    """A real option: finite and within [lo, hi] (within (lo, hi) if exclusive); returns it as a float."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{name} must be a number, not {value!r}") from None
    if not math.isfinite(x):
        raise UsageError(f"{name} must be finite, not {value!r}")
    if exclusive and not lo < x < hi:
        raise UsageError(f"{name} = {value!r} is out of range ({lo:g}, {hi:g})")
    if not lo <= x <= hi:
        raise UsageError(f"{name} = {value!r} is out of range [{lo:g}, {hi:g}]")
    return x


def count(name, value, lo=0, hi=10 ** 9):
    """An integer option within [lo, hi]; returns it as an int."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise UsageError(f"{name} must be an integer, not {value!r}")
    try:
        n = int(value)
    except (TypeError, ValueError):
        raise UsageError(f"{name} must be an integer, not {value!r}") from None
    if isinstance(value, float) and n != value:
        raise UsageError(f"{name} must be an integer, not {value!r}")
    if not lo <= n <= hi:
        raise UsageError(f"{name} = {value!r} is out of range [{lo}, {hi}]")
    return n


def physical_memory():
    """Bytes of memory of this machine (inf where the system does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return math.inf


def memory(what, n_bytes, limit=None):
    """Refuse options whose arrays need more than this machine's memory (or `limit` bytes):
    an impossible size is a usage error before the work, not a MemoryError after minutes."""
    limit = physical_memory() if limit is None else limit
    if n_bytes > limit:
        raise UsageError(f"{what} need about {n_bytes / 2**30:.3g} GiB of memory, more than this machine's "
                         f"{limit / 2**30:.3g} GiB: choose smaller values")
    return n_bytes


def shown(path):
    """A path as it can be printed, whatever its bytes."""
    return os.fsencode(str(path)).decode("utf-8", errors="backslashreplace")


def output(path, inputs=(), force=False, directory=False, what="output"):
    """Refuse, before any work, an output that cannot be written or would destroy something: a file output
    that is a symbolic link (writing it would write its target, whatever that is), among others.

    inputs: the command's input files (never overwritten, --force or not); directory: the output is a
    directory (made if missing) rather than a file; what: how the message names it ("catalog", ...).
    """
    text = str(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise UsageError(f"{shown(path)}: the {what} path is not valid UTF-8 (HDF5 and the run's lock need "
                         f"UTF-8 names); choose another name") from None
    if not text:
        raise UsageError(f"the {what} path is empty")
    for source in inputs:
        if os.path.exists(text) and os.path.exists(source) and os.path.samefile(text, source):
            raise UsageError(f"{text}: the {what} would overwrite the command's input {source}")
    if directory:
        if os.path.exists(text) and not os.path.isdir(text):
            raise UsageError(f"{text}: exists and is not a directory")
    elif os.path.islink(text):      # (writing it would write the file it points to)
        raise UsageError(f"{text}: is a symbolic link (to {os.readlink(text)}); an output is never written "
                         f"through a link: remove the link or give the {what} another name")
    elif os.path.isdir(text):
        raise UsageError(f"{text}: is a directory; give the {what} a file name")
    parent = os.path.dirname(os.path.abspath(text))
    if directory:   # an existing directory is written into; a missing one is made in its nearest ancestor
        parent = os.path.abspath(text) if os.path.isdir(text) else _existing_ancestor(parent)
    if not os.path.isdir(parent):
        raise UsageError(f"{text}: directory {parent} does not exist" if not os.path.exists(parent)
                         else f"{text}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise UsageError(f"{text}: cannot write in {parent}")
    if not directory and os.path.exists(text) and not force:
        raise UsageError(f"{text}: {what} exists (use --force to overwrite it)")
    return text


def _existing_ancestor(path):
    while not os.path.exists(path) and os.path.dirname(path) != path:
        path = os.path.dirname(path)
    return path


def write_text(path, text, what="file"):
    """Write `text` (UTF-8) to `path`, made or replaced (space.write_file: never through a symbolic link at `path`,
    whose target would be written); UsageError naming the file where it is a link or cannot be written."""
    try:
        space.write_file(path, text, f"the {what}")
    except OSError as err:
        if err.errno == errno.ELOOP:
            raise UsageError(f"{path}: is a symbolic link; the {what} is never written through a link: remove "
                             f"the link") from None
        raise UsageError(f"{path}: cannot write the {what} ({err.strerror})") from None
