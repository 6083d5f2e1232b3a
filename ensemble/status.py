"""`python -m ensemble status`: what a catalog holds, while it is written or after."""
import os

import numpy as np

from . import catalog
from .config import loads


def summary(path):
    """A text summary: config, per-task progress and provenance, totals."""
    final, partial = str(path), catalog.partial_path(path)
    if not os.path.exists(final) and os.path.exists(partial):
        path, state = partial, "in progress or interrupted"
    elif os.path.exists(final):
        state = "complete"
    else:
        raise catalog.CatalogError(f"{path}: no such catalog (nor {partial})")
    _, tasks, attrs = catalog.read(path)
    cfg = loads(attrs["config"])
    per_task = cfg.run.events
    lines = [f"{path}: {state}, version {attrs['version']}", ""]
    lines.append("task point seed     N      b      a       c   events  finished  rank  events/s")
    for k in range(len(tasks["point"])):
        written = int(tasks["events_written"][k])
        rate = tasks["events_per_second"][k]
        lines.append(f"{k:4d} {tasks['point'][k]:5d} {tasks['seed_index'][k]:4d} {tasks['N'][k]:5d} "
                     f"{tasks['b'][k]:6g} {tasks['a'][k]:6g} {tasks['c'][k]:7g} {written:8d}  "
                     f"{'yes' if written == per_task else 'no':>8s}  {tasks['rank'][k]:4d}  "
                     f"{'' if np.isnan(rate) else f'{rate:8.1f}'}")
    done = int(np.sum(tasks["events_written"] == per_task))
    lines += ["", f"tasks finished {done}/{len(tasks['point'])}, events recorded "
              f"{int(tasks['events_written'].sum())}/{len(tasks['point']) * per_task}", "",
              "config:", attrs["config"]]
    return "\n".join(lines)
