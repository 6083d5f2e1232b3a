"""Rank 0's decision, before any work, about the run's files: new, resumed, complete, or refused.

Made under the run's lock (lock.py) and broadcast, so that every rank acts alike (runner.py). A run is
refused (Refused, exit 2) when its output cannot become a catalog, exists without --force, or has an
interrupted run beside it without --resume; a resume is refused when its config differs from the
stored one. A catalog that does not fit on its disk (space.py) is refused before any HDF5 call.
"""
import errno
import os

import numpy as np

from .. import checks, filekind, space
from ..config import ConfigError, loads
from ..store import reader
from ..store.create import estimate_bytes
from ..store.errors import CatalogError
from ..store.schema import FAILED, FINISHED
from ..sweep import task_list
from .branching import spins_needed
from .lock import lock_path


class Refused(RuntimeError):
    """The run was refused before any work (output exists, is in use, or cannot be written)."""


def config_differences(stored_text, cfg, sections=("model", "run", "integrator")):
    """Keys (outside [output] and run.poll_seconds) whose values differ between the stored and the given config."""
    stored = loads(stored_text)
    diffs = []
    for section in sections:
        a, b = getattr(stored, section), getattr(cfg, section)
        for key in a.__dataclass_fields__:
            if getattr(a, key) != getattr(b, key) and key != "poll_seconds":
                diffs.append(f"{section}.{key}: stored {getattr(a, key)!r}, given {getattr(b, key)!r}")
    if stored.sweep != cfg.sweep:
        diffs.append(f"sweep: stored {stored.sweep!r}, given {cfg.sweep!r}")
    return diffs


def check_output(ctx):
    """Refuse, before the lock and any work, an output that cannot become a catalog (checks.output):
    a name that is not UTF-8, one of the run's inputs (its config), a directory, a symbolic link (the catalog,
    its .partial or its lock: never written through), a missing or read-only folder. Whether the catalog
    exists is prepare's to judge (--resume, --force)."""
    try:
        for p, what in ((ctx.path, "catalog"), (ctx.partial, "catalog"), (lock_path(ctx.path), "lock")):
            checks.output(p, inputs=ctx.inputs, force=True, what=what)
    except checks.UsageError as err:
        raise Refused(str(err)) from None


def prepare(ctx):
    """Rank 0's decision about the files (under the run's lock); returns (mode, message, spin-ups
    to run) or raises.

    ctx.rerun: the failed tasks are to be rerun with this [integrator] (which may differ from the stored one).
    """
    cfg, rerun = ctx.cfg, ctx.rerun
    final, partial = ctx.path, ctx.partial
    if ctx.resume:
        if not os.path.exists(partial):
            if os.path.exists(final):
                _, _, attrs = reader.read_tasks(final)
                diffs = config_differences(attrs["config"], cfg)
                if diffs:
                    raise ConfigError(f"{final}: --resume with a different config ({'; '.join(diffs)}); "
                                      f"the catalog is complete")
                return "complete", f"{final} is complete; nothing to resume", []
            raise Refused(f"{partial}: no interrupted run to resume")
        _, tasks, attrs = reader.read_tasks(partial, damaged_ok=True)
        diffs = config_differences(attrs["config"], cfg, ("model", "run") if rerun else
                                   ("model", "run", "integrator"))
        if diffs:
            raise ConfigError(f"{partial}: --resume with a different config ({'; '.join(diffs)})")
        if rerun is not None and not np.any(tasks["status"] == FAILED):
            raise ConfigError(f"{partial}: no failed task to rerun (a changed [integrator] applies to "
                              f"failed tasks only)")
        _fits(partial, lambda: space.reserve_file(partial))
        kept = (f"resuming {partial}: keeps {int(tasks['events_written'].sum())} of "
                f"{len(tasks['point']) * cfg.run.events} events recorded, "
                f"{int(np.sum(tasks['status'] == FINISHED))} of {len(tasks['point'])} tasks finished"
                + (f", {int(np.sum(tasks['status'] == FAILED))} failed" if np.any(tasks["status"] == FAILED) else ""))
        return "resume", kept, spins_needed(cfg, task_list(cfg), tasks, rerun)
    if os.path.exists(final) and not ctx.force:
        raise Refused(f"{final}: catalog exists (use --force to overwrite it)")
    for p in (final, partial):
        kind = filekind.identify(p)[0]
        if ctx.force and kind not in ("missing", "catalog", "damaged", "empty"):
            # (a config, a summary or any other file given as -o is never replaced)
            raise Refused(f"{p} {filekind.describe(p)}; --force replaces only an event catalog")
    if os.path.exists(partial) and not ctx.force:
        raise Refused(f"{partial}: an interrupted run exists (use --resume to continue it, "
                      f"--force to start over)")
    tasks = task_list(cfg)
    _fits(partial, lambda: space.check_fits(partial, estimate_bytes(cfg, tasks)))
    return "new", None, spins_needed(cfg, tasks)


def _fits(partial, check):
    """Run a space check (space.py) before any HDF5 call; a catalog that does not fit, or cannot be written at all
    (a read-only file or file system: not a matter of space), is refused on every rank alike."""
    try:
        check()
    except OSError as err:
        if err.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
            raise CatalogError(f"{partial}: cannot be written ({err.strerror}); a run writes its catalog there",
                               collective=True) from None
        raise CatalogError(f"{partial}: the catalog does not fit ({err.strerror or err})", collective=True) from None
