"""Catalogs written through the project's own writer (writers.Rank0Writer on one process) from
given events: real, verified catalogs whose contents a test chooses."""
import itertools

import numpy as np

from ensemble.store import schema, writers
from ensemble.store.checkpoint import Checkpoint, carries_creep
from ensemble.config import loads
from ensemble.model.workspace import Workspace
from ensemble.run.trajectory import integrator_text
from ensemble.sweep import task_list


def write_events(path, config_text, parts, streams=None):
    """A catalog of the config's tasks; task k gets the events parts[k] (dict of columns, its
    rows' `task` column k; without `kind` and `ending`: inertial events), committed in batches of
    varying size. Tasks with run.events events are finished with provenance seed_entropy, spawn_key =
    streams[k] (default: the runner's, run.seed and k); the others are left open (an empty task never
    committed)."""
    from mpi4py import MPI
    cfg = loads(config_text)
    tasks = task_list(cfg)
    assert len(tasks) == len(parts)
    streams = streams or [(cfg.run.seed, t.index) for t in tasks]
    writer = writers.Rank0Writer(str(path), MPI.COMM_SELF, cfg, tasks, integrator_text(cfg.integrator))
    for task, ev in zip(tasks, parts):
        n = len(ev["t"])
        writer.record(task.index)
        start, sizes = 0, itertools.cycle(np.roll([1, 57, 100, 13], task.index))
        N = task.model.N
        creep = np.zeros(Workspace.creep_size(N)) if carries_creep(task.model) else None
        ev = {**{name: np.full(n, value, dtype=schema.EVENT_FIELDS[name])
                 for name, value in schema.SUPPLIED.items()}, **ev}
        while start < n:
            size = min(int(next(sizes)), n - start)
            state = Checkpoint(np.zeros(N), np.zeros(N), np.zeros((N, 2)), np.zeros(2),
                                       cfg.run.transient + start + size, creep)
            writer.commit(task.index, start, {c: v[start:start + size] for c, v in ev.items()}, state)
            start += size
        if n == cfg.run.events:
            entropy, key = streams[task.index]
            writer.finish(task.index, {"rank": 0, "wall_time": 1.0, "events_per_second": 1.0,
                                       "seed_entropy": entropy, "spawn_key": key})
    writer.close()
