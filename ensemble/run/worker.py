"""One rank's work: take items from the shared counter (work), and integrate each task or spin-up
(TaskRunner): kernel calls sized in time, a buffer, commits with checkpoints.

A task that fails numerically (SimulationError) is recorded as failed in the catalog and the rank goes
on with the next task. The loop (TaskRunner._integrate) sizes each kernel call to last about
run.poll_seconds, so that stop requests, progress and checkpoints are served in time whatever an event
costs.
"""
import sys
import time

import numpy as np

from ..store.checkpoint import Checkpoint
from ..store.errors import CatalogError
from ..store.schema import FAILED, FINISHED
from ..model.workspace import UNLIMITED
from ..sweep import point_tasks
from .branching import branch_start
from .trajectory import SimulationError, Trajectory, event_rows, integrator_text, parse_integrator

# work budget of a kernel call, in block-steps (chain.simulate): ~0.05 s at the ~200 ns per
# block-step of the adaptive methods (benchmarks/results/step_budget_*); then sized by time
FIRST_BUDGET = 250_000
MIN_BUDGET = 1_000
# a rank whose task has made no row for this long says where its chain is (an event in progress, a creep phase),
# then again after four times as long, and so on: no run goes quiet without saying why
QUIET_SECONDS = 60.0


class TaskRunner:
    """Integrates one task on this rank: kernel calls, buffer, flushes with checkpoints.

    ctx: the run's context (context.py) with its writer, coordinator and progress. `failed` lists the
    tasks that failed on this rank; ctx.rerun is an [integrator] for tasks that failed before (rerun
    from their start), or None.
    """

    def __init__(self, ctx):
        self.ctx = ctx
        self.cfg, self.writer, self.coord, self.progress = ctx.cfg, ctx.writer, ctx.coord, ctx.progress
        self.rerun = ctx.rerun
        self.failed = []      # (task index, message) of the tasks that failed on this rank
        self.io_time = 0.0    # seconds spent handing events and checkpoints to the writer
        self.spun = {}        # run.branch: point -> its spun-up state (Checkpoint), once all are known
        self.spin_failed = {}  # run.branch: point -> why its spin-up failed in this run

    def run(self, task):
        """Returns True if the task finished or failed, False if a stop request interrupted it."""
        try:
            return self._run(task)
        except SimulationError as err:
            self.writer.fail(task.index, str(err))
            self.failed.append((task.index, str(err)))
            print(f"error: rank {self.coord.rank}: {err}; the task is recorded as failed, the "
                  f"others go on", file=sys.stderr, flush=True)
            self.coord.task_done()
            return True
        except CatalogError:
            raise
        except Exception as err:
            raise RuntimeError(f"task {task.index}: {type(err).__name__}: {err}") from err

    def _take_up(self, task):
        """(Trajectory, events written) to continue, or None if there is nothing to do."""
        cfg = self.cfg
        where = f"task {task.index}"
        if cfg.run.branch and task.point in self.spin_failed:
            return None     # recorded as failed (and counted) by the rank that spun its point up
        rec = self.writer.record(task.index)
        if rec.damaged:     # (store/tables.py) a damaged byte, or a run killed while writing the record
            print(f"note: rank {self.coord.rank}: task {task.index}: {rec.damaged}; it is rerun from its start",
                  file=sys.stderr, flush=True)
            self.writer.start(task.index, integrator_text(cfg.integrator))
            return Trajectory(cfg, task, self._start(task), histories=0), 0
        if rec.status == FAILED:
            if self.rerun is None or (cfg.run.branch and task.point not in self.spun):
                self.failed.append((task.index, rec.error))
                return None
            rec = self.writer.record(task.index, restart=True)
            self.writer.start(task.index, integrator_text(self.rerun))
            return Trajectory(cfg, task, self._start(task), self.rerun, histories=0), 0
        if rec.checkpoint is not None:
            self.coord.count_events(rec.checkpoint.done, resumed=True)
        if rec.written >= cfg.run.events:
            if rec.status != FINISHED:   # stopped between its last commit and the finish record
                self.writer.finish(task.index, {})
            return None
        checkpoint = rec.checkpoint if rec.checkpoint is not None else self._start(task)
        return (Trajectory(cfg, task, checkpoint, parse_integrator(rec.integrator, where), histories=rec.histories),
                rec.written)

    def _start(self, task):
        """The state a task starts from: None (its own initial state), or after branching its point's
        spun-up state with the task's own perturbation."""
        if not self.cfg.run.branch:
            return None
        return branch_start(self.cfg, task, self.spun[task.point])

    def _run(self, task):
        taken = self._take_up(task)
        if taken is None:
            self.coord.task_done()
            return True
        traj, written = taken
        wall = time.perf_counter()
        rate = self._integrate(task.index, traj, written, self.cfg.run.events)
        if rate is None:
            return False
        self.writer.finish(task.index, {
            "rank": self.coord.rank, "wall_time": time.perf_counter() - wall,
            "events_per_second": rate, "seed_entropy": self.cfg.run.seed, "spawn_key": task.index})
        self.coord.task_done()
        return True

    def spin_up(self, spin, tasks):
        """Spin up a point (or read its finished spin-up): its state after run.transient events
        (Checkpoint), the error message if it failed (its point's tasks are then recorded as failed),
        or None if a stop request interrupted it (checkpointed). spin: the Spin; tasks: all tasks."""
        cfg = self.cfg
        record = len(tasks) + spin.point
        rec = self.writer.record(record)
        if rec.checkpoint is not None and rec.checkpoint.done >= cfg.run.transient:
            self.coord.task_done()
            return rec.checkpoint
        integrator = cfg.integrator
        if spin.rerun and self.rerun is not None:   # it failed: from its start with the rerun's integrator
            rec, integrator = self.writer.record(record, restart=True), self.rerun
        if rec.checkpoint is not None:
            self.coord.count_events(rec.checkpoint.done, resumed=True)
        traj = Trajectory(cfg, spin.task, rec.checkpoint, integrator, label=f"spin-up of point {spin.point}",
                          discarded=cfg.run.transient)
        try:
            if self._integrate(record, traj, 0, 0) is None:
                return None
        except SimulationError as err:
            message = str(err)
            for task in point_tasks(cfg, tasks, spin.point):
                self.writer.fail(task.index, message)
                self.failed.append((task.index, message))
            print(f"error: rank {self.coord.rank}: {message}; the tasks of point {spin.point} are recorded "
                  f"as failed, the others go on", file=sys.stderr, flush=True)
            self.coord.task_done()
            return message
        self.coord.task_done()
        return traj.checkpoint()

    def _integrate(self, record, traj, written, events):
        """Integrate a trajectory until it has recorded `events` after its `traj.discarded`, committing
        to catalog record `record` as it goes; its recorded events per second of kernel time, or
        None if a stop request interrupted it (checkpointed)."""
        cfg = self.cfg
        total = traj.discarded + events
        buffer = []
        buffered = 0
        histories = []      # (slot, history) of buffered rows (Trajectory.new_histories)
        chunk = 4
        budget = FIRST_BUDGET
        last_flush = time.perf_counter()
        record_time = 0.0
        recorded_here = 0
        quiet_since, quiet_note = time.perf_counter(), QUIET_SECONDS

        def flush():
            nonlocal buffer, buffered, written, last_flush, histories
            start = time.perf_counter()
            batch = ({name: np.concatenate([b[name] for b in buffer]) for name in buffer[0]}
                     if buffer else None)
            self.writer.commit(record, written, batch, traj.checkpoint(), histories)
            written += buffered
            buffer, buffered, histories = [], 0, []
            last_flush = time.perf_counter()
            self.io_time += last_flush - start

        while traj.done < total:
            if self.coord.poll():
                flush()
                return None
            self.writer.poll()
            recording = traj.done >= traj.discarded
            phase_left = (total if recording else traj.discarded) - traj.done
            n = min(chunk, phase_left, cfg.output.batch - buffered)
            t0 = time.perf_counter()
            out = traj.advance(n, budget)
            elapsed = time.perf_counter() - t0
            k = len(out[0])
            # Size the next kernel call to last about poll_seconds: by events while they are
            # cheap, by work (budget, in block-steps) when one event is long, so that signals,
            # progress and checkpoints are served in time whatever an event costs.
            scale = cfg.run.poll_seconds / max(elapsed, 1e-6)
            if k < n:
                budget = int(np.clip(budget * min(scale, 4.0), MIN_BUDGET, UNLIMITED))
            chunk = int(np.clip(max(k, 1) * scale, 1, cfg.output.batch))
            self.coord.count_events(k)
            if recording and k:
                record_time += elapsed
                recorded_here += k
                buffer.append(event_rows(traj.task, *out))
                buffered += k
                histories += traj.new_histories
                traj.new_histories = []
            now = time.perf_counter()
            if k:
                quiet_since, quiet_note = now, QUIET_SECONDS
            elif now - quiet_since >= quiet_note:
                print(f"note: rank {self.coord.rank}: {traj.label}: no row for {now - quiet_since:.0f} s; "
                      f"{traj.where()}", flush=True)
                quiet_note *= 4
            if buffered >= cfg.output.batch or now - last_flush >= cfg.output.flush_seconds:
                flush()
            self.progress.maybe_print()
        flush()
        return recorded_here / max(record_time, 1e-9)


def work(ctx, tasks, spins, worker):
    """Take work until none is left (or a stop request): first the spin-ups (run.branch), then, once
    all are done and their states known on every rank, the tasks. Returns (busy, idle) seconds.

    One counter numbers the work: items [0, len(spins)) are the spin-ups, then the tasks.
    """
    coord = ctx.coord
    busy = idle = 0.0
    first = len(spins)
    total = first + len(tasks)
    stopped = coord.poll()
    mine = {}
    k = total
    while not stopped:
        k = coord.next_task()
        if k >= first:
            break
        t0 = time.perf_counter()
        mine[spins[k].point] = state = worker.spin_up(spins[k], tasks)
        stopped = state is None
        busy += time.perf_counter() - t0
    if spins:
        idle += _wait(ctx, first)
        # one decision for all: a stop seen by some ranks only must not split the collective below
        if any(ctx.comm.allgather(coord.poll())):
            return busy, idle
        for part in ctx.comm.allgather(mine):
            for point, state in part.items():
                (worker.spun if isinstance(state, Checkpoint) else worker.spin_failed)[point] = state
        stopped = False
    while not stopped and k < total:
        t0 = time.perf_counter()
        stopped = not worker.run(tasks[k - first])
        busy += time.perf_counter() - t0
        if not stopped:
            k = coord.next_task()
    return busy, idle + _wait(ctx, total)


def _wait(ctx, count):
    """Keep serving MPI (and rank 0's writer) until `count` items are done or a stop is requested;
    returns the seconds waited."""
    waited = time.perf_counter()
    while not ctx.coord.poll() and ctx.coord.tasks_done() < count:
        ctx.writer.poll()
        ctx.progress.maybe_print()
        time.sleep(0.05)
    return time.perf_counter() - waited

