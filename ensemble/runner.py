"""A run on every rank: take tasks, integrate them in kernel calls, buffer, checkpoint, write.

The same code runs serially (one rank, no mpirun) and under MPI. Each task is
one trajectory on one rank; its seed comes from its index, so results do not
depend on the number of ranks or on which rank ran a task.
"""
import os
import time

import numpy as np

from . import catalog
from .catalog import Checkpoint, CatalogError
from .config import ConfigError, loads
from .integrators import kernel_args
from .model.chain import simulate
from .model.workspace import (D_DURATION, D_FIRST, D_LAST, D_NSLIP, D_SLIP, NDIAG, OK, PAUSED,
                              STATUS_TEXT, UNLIMITED, Workspace)
from .parallel import Coordinator
from .tasks import initial_state, task_list

EXIT_INTERRUPTED = 75   # checkpointed after a signal; continue with --resume (EX_TEMPFAIL)


class SimulationError(RuntimeError):
    """A task that cannot go on; the message names the task and the event."""


class Trajectory:
    """One task's chain between events: its workspace, clock and event counter."""

    def __init__(self, cfg, task, checkpoint=None):
        self.cfg = cfg
        self.task = task
        self.ws = Workspace(task.model.N)
        if checkpoint is None:
            self.ws.load(*initial_state(cfg, task))
            self.clock = np.zeros(2)
            self.done = 0      # events completed, transient included
        else:
            self.ws.load(checkpoint.force, checkpoint.psi, checkpoint.since)
            self.clock = checkpoint.clock.copy()
            self.done = checkpoint.done
        self.args = kernel_args(task.model, cfg.integrator)

    def checkpoint(self):
        """The state after the last completed event (also while an event is paused)."""
        force, psi, since, clock = self.ws.between_events(self.clock)
        return Checkpoint(force, psi, since, clock, self.done)

    def state(self):
        """(force, psi) of every block now (between events), c-free frame."""
        return self.ws.state(self.clock, self.task.model.nu)

    def advance(self, n, budget=UNLIMITED):
        """Run n events; returns (onset times, epicenters, diagnostics rows).

        With a work `budget` (chain.simulate) fewer events may be returned: the call stops
        when the budget is spent, possibly in the middle of an event, which the next call continues.
        """
        t = np.empty(n)
        epicenter = np.empty(n, dtype=np.int64)
        diag = np.empty((n, NDIAG))
        ws = self.ws
        status, k = simulate(*ws.arrays, self.clock, *self.args, n, budget, t, epicenter, diag)
        if status not in (OK, PAUSED):
            where = self.done + k
            phase = "transient " if where < self.cfg.run.transient else ""
            raise SimulationError(f"task {self.task.index} {phase}event {where}: {STATUS_TEXT[status]} "
                                  f"(method={self.cfg.integrator.method}, dt={self.cfg.integrator.dt})")
        self.done += k
        return t[:k], epicenter[:k], diag[:k]


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


class Progress:
    """Rank 0's progress line at a steady interval (fit for a log file)."""

    def __init__(self, coord, n_tasks, total_events, every, log):
        self.coord, self.n_tasks, self.total, self.every, self.log = coord, n_tasks, total_events, every, log
        self.start = time.perf_counter()
        self.last = self.start

    def maybe_print(self, tasks=None):
        """Print if the interval has passed (or always, given the final task count)."""
        now = time.perf_counter()
        if self.coord.rank != 0 or (tasks is None and now - self.last < self.every):
            return
        self.last = now
        tasks = self.coord.tasks_done() if tasks is None else tasks
        events = self.coord.events_total
        rate = (events - self.coord.events_resumed) / max(now - self.start, 1e-9)
        left = (self.total - events) / rate if rate > 0 else float("inf")
        eta = f"{left / 60:.1f} min" if np.isfinite(left) else "?"
        self.log(f"progress: tasks {tasks}/{self.n_tasks}, events {events}/{self.total} "
                 f"(incl. transient), {rate:.1f} events/s, {eta} left")


class TaskRunner:
    """Integrates one task on this rank: kernel calls, buffer, flushes with checkpoints."""

    def __init__(self, cfg, writer, coord, progress):
        self.cfg, self.writer, self.coord, self.progress = cfg, writer, coord, progress
        self.io_time = 0.0    # seconds spent handing events and checkpoints to the writer

    def run(self, task):
        """Returns True if the task finished, False if a stop request interrupted it."""
        try:
            return self._run(task)
        except SimulationError:
            raise
        except Exception as err:
            raise RuntimeError(f"task {task.index}: {type(err).__name__}: {err}") from err

    def _run(self, task):
        cfg = self.cfg
        cp, written = self.writer.resume_point(task.index, task.model.N)
        if cp is not None:
            self.coord.count_events(cp.done, resumed=True)
        if written >= cfg.run.events:
            self.coord.task_done()
            return True
        traj = Trajectory(cfg, task, cp)
        total = cfg.run.transient + cfg.run.events
        buffer = []
        buffered = 0
        chunk = 4
        wall = time.perf_counter()
        last_flush = wall
        record_time = 0.0
        recorded_here = 0

        def flush():
            nonlocal buffer, buffered, written, last_flush
            start = time.perf_counter()
            batch = ({name: np.concatenate([b[name] for b in buffer]) for name in buffer[0]}
                     if buffer else None)
            self.writer.commit(task.index, written, batch, traj.checkpoint())
            written += buffered
            buffer, buffered = [], 0
            last_flush = time.perf_counter()
            self.io_time += last_flush - start

        while traj.done < total:
            if self.coord.poll():
                flush()
                return False
            self.writer.poll()
            recording = traj.done >= cfg.run.transient
            phase_left = (total if recording else cfg.run.transient) - traj.done
            n = min(chunk, phase_left, cfg.output.batch - buffered)
            t0 = time.perf_counter()
            out = traj.advance(n)
            elapsed = time.perf_counter() - t0
            # size the next kernel call to last about poll_seconds
            chunk = int(np.clip(n * cfg.run.poll_seconds / max(elapsed, 1e-6), 1, cfg.output.batch))
            self.coord.count_events(n)
            if recording:
                record_time += elapsed
                recorded_here += n
                buffer.append(event_rows(task, *out))
                buffered += n
            now = time.perf_counter()
            if buffered >= cfg.output.batch or now - last_flush >= cfg.output.flush_seconds:
                flush()
            self.progress.maybe_print()
        flush()
        self.writer.finish(task.index, {
            "rank": self.coord.rank, "wall_time": time.perf_counter() - wall,
            "events_per_second": recorded_here / max(record_time, 1e-9),
            "seed_entropy": cfg.run.seed, "spawn_key": task.index})
        self.coord.task_done()
        return True


def _same_config(stored_text, cfg):
    """Keys (outside [output]) whose values differ between the stored and the given config."""
    stored = loads(stored_text)
    diffs = []
    for section in ("model", "run", "integrator"):
        a, b = getattr(stored, section), getattr(cfg, section)
        for key in a.__dataclass_fields__:
            if getattr(a, key) != getattr(b, key) and key != "poll_seconds":
                diffs.append(f"{section}.{key}: stored {getattr(a, key)!r}, given {getattr(b, key)!r}")
    if stored.sweep != cfg.sweep:
        diffs.append(f"sweep: stored {stored.sweep!r}, given {cfg.sweep!r}")
    return diffs


def _prepare(cfg, path, resume, force):
    """Rank 0's decision about the files; returns (mode, message) or raises."""
    final, partial = str(path), catalog.partial_path(path)
    if resume:
        if not os.path.exists(partial):
            if os.path.exists(final):
                return "complete", f"{final} is complete; nothing to resume"
            raise CatalogError(f"{partial}: no interrupted run to resume")
        _, _, attrs = catalog.read(partial)
        diffs = _same_config(attrs["config"], cfg)
        if diffs:
            raise ConfigError(f"{partial}: --resume with a different config ({'; '.join(diffs)})")
        return "resume", None
    if os.path.exists(final) and not force:
        raise CatalogError(f"{final}: catalog exists (use --force to overwrite it)")
    if os.path.exists(partial) and not force:
        raise CatalogError(f"{partial}: an interrupted run exists (use --resume to continue it, "
                           f"--force to start over)")
    return "new", None


def run(cfg, path, comm, resume=False, force=False, log=print):
    """Run every task of cfg on the ranks of comm into the catalog at `path`.

    Writes to path + '.partial' and renames it to `path` when every task is
    done, so a good catalog is never replaced by a half-written one. Returns 0,
    or EXIT_INTERRUPTED after a stop request (every rank checkpointed).
    """
    rank = comm.Get_rank()
    say = log if rank == 0 else (lambda *a, **k: None)
    decision = None
    if rank == 0:
        try:
            decision = _prepare(cfg, path, resume, force)
        except (CatalogError, ConfigError) as err:
            decision = err
    decision = comm.bcast(decision, root=0)
    if isinstance(decision, Exception):
        raise decision
    mode, message = decision
    if mode == "complete":
        say(message)
        return 0
    tasks = task_list(cfg)
    Writer = catalog.choose_writer(cfg.output.writer, comm)
    partial = catalog.partial_path(path)
    say(f"writing {partial} with {comm.Get_size()} rank(s): "
        f"{Writer.name if comm.Get_size() > 1 else 'serial HDF5'}")
    t_start = time.perf_counter()
    if mode == "new":
        writer = Writer(partial, comm, cfg, tasks)
    else:
        writer = Writer(partial, comm)
    # event counts reach rank 0 as messages: about 100 per second in all, however many ranks
    coord = Coordinator(comm, report_seconds=min(max(1.0, comm.Get_size() / 100),
                                                  cfg.output.progress_seconds / 2))
    coord.install_signal_handlers()
    progress = Progress(coord, len(tasks), len(tasks) * (cfg.run.transient + cfg.run.events),
                        cfg.output.progress_seconds, log)
    worker = TaskRunner(cfg, writer, coord, progress)
    try:
        busy, idle = _work(tasks, worker, writer, coord, progress)
    except BaseException:
        if comm.Get_size() == 1:   # with more ranks the caller aborts them all
            writer.close()
            coord.close()
        raise
    finally:
        coord.restore_signal_handlers()
    writer.close()   # first: rank 0 may still have to receive rows from the others
    # every rank counted its finished tasks before it could pass the collective close
    done = coord.tasks_done()
    stopped = done < len(tasks)
    coord.close()
    progress.maybe_print(tasks=done)
    per_rank = comm.gather((busy, idle, coord.rma_wait, worker.io_time), root=0)
    elapsed = time.perf_counter() - t_start
    if rank == 0:
        for r, (b, i, w, io) in enumerate(per_rank):
            log(f"rank {r}: busy {b:.1f} s (of which {io:.2f} s writing, {w:.2f} s waiting for the "
                f"task counter), idle {i:.1f} s at the end")
        if stopped:
            log(f"interrupted ({coord.signal_name}): every rank checkpointed into {partial}; "
                f"continue with --resume")
        else:
            os.replace(partial, str(path))
            log(f"wrote {path}: {len(tasks)} tasks, {len(tasks) * cfg.run.events} events in {elapsed:.1f} s")
    return EXIT_INTERRUPTED if stopped else 0


def _work(tasks, worker, writer, coord, progress):
    """Take tasks until none is left (or a stop request); returns (busy, idle) seconds."""
    busy = 0.0
    stopped = False
    while not stopped:
        k = coord.next_task()
        if k >= len(tasks):
            break
        t0 = time.perf_counter()
        stopped = not worker.run(tasks[k])
        busy += time.perf_counter() - t0
    # Nothing left to take: keep serving MPI (and rank 0's writer) until all are done.
    waited = time.perf_counter()
    while not coord.poll() and coord.tasks_done() < len(tasks):
        writer.poll()
        progress.maybe_print()
        time.sleep(0.05)
    return busy, time.perf_counter() - waited

