"""Run tasks: config -> initial state -> kernel in batches -> catalog."""
import math
import os
import time

import numpy as np

from . import catalog
from .integrators import INTEGRATORS
from .model.workspace import (D_DURATION, D_FIRST, D_LAST, D_NSLIP, D_SLIP, NDIAG, OK,
                              STATUS_TEXT, Workspace)
from .tasks import initial_state, task_list


class SimulationError(RuntimeError):
    """A task that cannot go on; the message names the task and the event."""


class Trajectory:
    """One task's chain between events: its workspace, clock and event counter."""

    def __init__(self, cfg, task):
        self.cfg = cfg
        self.task = task
        self.kernel = INTEGRATORS[cfg.integrator.method].simulate
        self.ws = Workspace(task.model.N)
        self.ws.load(*initial_state(cfg, task))
        self.clock = np.zeros(2)
        self.done = 0          # events completed, transient included
        m, it = task.model, cfg.integrator
        self.args = (m.l * m.l, m.nu, m.a, m.b, it.dt, it.max_duration,
                     int(min(2 * it.max_duration / it.dt + 1e6, 2**62)))

    def advance(self, n):
        """Run n events; returns (onset times, epicenters, diagnostics rows)."""
        t = np.empty(n)
        epicenter = np.empty(n, dtype=np.int64)
        diag = np.empty((n, NDIAG))
        ws = self.ws
        status, k = self.kernel(ws.W, ws.act, ws.flag, ws.touched, ws.stuck, ws.diag, self.clock,
                                *self.args, n, t, epicenter, diag)
        if status != OK:
            where = self.done + k
            phase = "transient " if where < self.cfg.run.transient else ""
            raise SimulationError(f"task {self.task.index} {phase}event {where}: {STATUS_TEXT[status]} "
                                  f"(method={self.cfg.integrator.method}, dt={self.cfg.integrator.dt})")
        self.done += n
        return t, epicenter, diag


def event_rows(task, t, epicenter, diag):
    """Kernel output -> catalog columns (see catalog.EVENT_FIELDS)."""
    first = diag[:, D_FIRST].astype(np.int64)
    last = diag[:, D_LAST].astype(np.int64)
    return {
        "task": np.full(len(t), task.index, dtype=np.int64), "t": t, "epicenter": epicenter,
        "mu": np.log10(diag[:, D_SLIP]), "slip": diag[:, D_SLIP], "first": first, "last": last,
        "n_slipped": diag[:, D_NSLIP].astype(np.int64),
        "boundary": (first == 0) | (last == task.model.N - 1), "duration": diag[:, D_DURATION],
    }


def run_task(cfg, task, writer, log=print):
    """Integrate one task: discard the transient, record `run.events` events in batches."""
    traj = Trajectory(cfg, task)
    batch = cfg.output.batch
    left = cfg.run.transient
    while left > 0:
        traj.advance(min(batch, left))
        left -= min(batch, left)
    written = 0
    start = time.perf_counter()
    while written < cfg.run.events:
        n = min(batch, cfg.run.events - written)
        writer.write(task.index, written, event_rows(task, *traj.advance(n)))
        written += n
    rate = written / max(time.perf_counter() - start, 1e-9)
    log(f"task {task.index} done: {written} events ({rate:.1f} events/s recorded)")


def run_serial(cfg, path, force=False, log=print):
    """Run every task in this process into the catalog at `path`.

    Writes to path + '.partial' and renames it to `path` only when every task is
    done, so an existing catalog is never left half-overwritten.
    """
    path = str(path)
    if os.path.exists(path) and not force:
        raise catalog.CatalogError(f"{path}: catalog exists (use --force to overwrite it)")
    tasks = task_list(cfg)
    tmp = catalog.partial_path(path)
    writer = catalog.SerialWriter(tmp, cfg, tasks)
    t0 = time.perf_counter()
    try:
        for task in tasks:
            run_task(cfg, task, writer, log)
    finally:
        writer.close()
    os.replace(tmp, path)
    total = len(tasks) * cfg.run.events
    elapsed = time.perf_counter() - t0
    log(f"wrote {path}: {len(tasks)} tasks, {total} events in {elapsed:.1f} s "
        f"({(len(tasks) * (cfg.run.events + cfg.run.transient)) / max(elapsed, 1e-9):.1f} events/s incl. transient)")
    return path
