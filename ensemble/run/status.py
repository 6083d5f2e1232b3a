"""`python -m ensemble status`: what a catalog holds and what its run is doing.

The state of a run comes from its files: the lock (lock.py) says whether a run
is alive and carries its latest progress line (a few seconds old at most); the
catalog's commit rows say what each task has stored; the final name exists only
once every task has finished. The catalog is read without taking HDF5's file
lock, so this works while any writer is writing it.
"""
import os

import numpy as np

from . import lock
from ..store import reader, schema
from ..store.errors import CatalogError
from ..store.files import partial_path
from ..config import loads

RESUME = "python -m ensemble resume"


def _state(path):
    """(file to read or None, one-line state) of the run whose final catalog is `path`."""
    final, partial = str(path), partial_path(path)
    info = lock.read_info(final)
    if lock.is_held(final):
        line = f"running ({lock.describe(info)})"
        if info.get("progress"):
            line += f"\n  progress: {info['progress']}"
        return (partial if os.path.exists(partial) else None), line
    if os.path.exists(partial):
        died = f" (its run died: lock file {lock.lock_path(final)} left behind)" if info else ""
        return partial, f"interrupted{died}; continue with `{RESUME} {final}`"
    if os.path.exists(final):
        return final, "complete"
    raise CatalogError(f"{final}: no such catalog (nor {partial})")


def summary(path):
    """A text summary: state, per-task progress and provenance, totals, config."""
    path = str(path).removesuffix(".partial")
    source, state = _state(path)
    if source is None:
        return f"{path}: {state}\n(the catalog is being created)"
    with reader.Reader(source) as cat:
        per_task, tasks, attrs, spinups = cat.per_task, cat.tasks, cat.attrs, cat.spinups
    cfg = loads(attrs["config"])
    failed = np.flatnonzero(tasks["status"] == schema.FAILED)
    if len(failed) and not state.startswith("running"):
        state = (f"failed: tasks {', '.join(map(str, failed))} (the others go on with `{RESUME} {path}`; "
                 f"rerun the failed ones with `{RESUME} {path} --set integrator.KEY=VALUE`)")
    lines = [f"{source}: {state}", f"version {attrs['version']}, format {attrs['format']}", ""]
    keys = cfg.model.law_keys()     # one law per catalog (model.law is not swept)
    lines.append("task point seed     N " + "".join(f"{k:>8s}" for k in keys)
                 + "   events  recorded    status  rank  events/s")
    total = cfg.run.discarded + cfg.run.events
    for k in range(len(tasks["point"])):
        written = int(tasks["events_written"][k])
        rate = tasks["events_per_second"][k]
        st = schema.STATUS_NAMES[int(tasks["status"][k])]
        lines.append(f"{k:4d} {tasks['point'][k]:5d} {tasks['seed_index'][k]:4d} {tasks['N'][k]:5d} "
                     + "".join(f"{tasks[key][k]:8g}" for key in keys) + " "
                     f"{int(tasks['events_done'][k]):8d} {written:9d} {st:>9s}  {tasks['rank'][k]:4d}  "
                     f"{'' if np.isnan(rate) else f'{rate:8.1f}'}")
    for k in failed:
        lines.append(f"  task {k} failed: {tasks['error'][k]}")
    done = int(np.sum(tasks["status"] == schema.FINISHED))
    for point, spun in zip(spinups.get("point", []), spinups["events_done"]):
        lines.append(f"spin-up of point {point}: {spun}/{cfg.run.transient} events "
                     f"({'done' if spun >= cfg.run.transient else 'not done'}; its tasks branch from it)")
    discarded = (f"the decorrelation stretch of {cfg.run.decorrelation} after branching" if cfg.run.branch
                 else f"the transient of {cfg.run.transient}")
    lines += ["", f"(events: done incl. {discarded}, as of each task's last checkpoint; of {total} per task)",
              f"tasks finished {done}/{len(tasks['point'])}, events recorded "
              f"{int(tasks['events_written'].sum())}/{len(tasks['point']) * per_task}", "",
              "config:", attrs["config"]]
    return "\n".join(lines)
