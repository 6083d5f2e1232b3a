"""Rank 0's progress line: at a steady interval in the log, fresher in the run's lock file (lock.py)."""
import time

import numpy as np


class Progress:
    """Rank 0's progress: a line at a steady interval (fit for a log file), fresher in the lock file.

    coord: the run's Coordinator (parallel.py), whose counts it reads; n_tasks: work items (spin-ups
    and tasks); total_events: events of all of them, transients included.
    """

    LOCK_SECONDS = 2.0

    def __init__(self, coord, n_tasks, total_events, every, log, lock=None):
        self.coord, self.n_tasks, self.total, self.every, self.log = coord, n_tasks, total_events, every, log
        self.lock = lock
        self.start = time.perf_counter()
        self.last = self.start
        self.last_lock = -np.inf

    @classmethod
    def of_run(cls, ctx, coord, tasks, spins):
        """The progress of the run `ctx` (context.py) over its spin-ups and tasks."""
        run = ctx.cfg.run
        return cls(coord, len(spins) + len(tasks),
                   len(spins) * run.transient + len(tasks) * (run.discarded + run.events),
                   ctx.cfg.output.progress_seconds, ctx.log, ctx.lock)

    def restart_clock(self):
        """Rates and time left count from here (after the kernels are compiled)."""
        self.start = self.last = time.perf_counter()

    def line(self, tasks=None):
        now = time.perf_counter()
        tasks = self.coord.tasks_done() if tasks is None else tasks
        events = self.coord.events_total
        rate = (events - self.coord.events_resumed) / max(now - self.start, 1e-9)
        left = (self.total - events) / rate if rate > 0 else float("inf")
        eta = f"{left / 60:.1f} min" if np.isfinite(left) else "?"
        return (f"tasks {tasks}/{self.n_tasks}, events {events}/{self.total} "
                f"(incl. transient), {rate:.1f} events/s, {eta} left")

    def maybe_print(self, tasks=None):
        """Print if the interval has passed (or always, given the final task count)."""
        if self.coord.rank != 0:
            return
        now = time.perf_counter()
        if self.lock is not None and (tasks is not None or now - self.last_lock >= self.LOCK_SECONDS):
            self.last_lock = now
            self.lock.progress(self.line(tasks))
        if tasks is None and now - self.last < self.every:
            return
        self.last = now
        self.log("progress: " + self.line(tasks))
