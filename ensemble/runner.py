"""A run on every rank: take tasks, integrate them in kernel calls, buffer, checkpoint, write.

The same code runs serially (one rank, no mpirun) and under MPI. Each task is
one trajectory on one rank; its seed comes from its index, so results do not
depend on the number of ranks or on which rank ran a task.
"""
import glob
import os
import sys
import time
import tomllib

import numpy as np

from . import checks, environment, filekind, space
from .store import reader, writers
from .store.checkpoint import Checkpoint, carries_creep
from .store.create import estimate_bytes
from .store.errors import CatalogError
from .store.files import partial_path
from .store.schema import FAILED, FINISHED
from .config import ConfigError, from_dict, loads, section_lines
from .integrators import kernel_params
from .lock import RunLock
from .model.chain import simulate
from .model.workspace import (D_DURATION, D_ENDING, D_FIRST, D_KIND, D_LAST, D_NSLIP, D_SLIP, NDIAG, OK, PAUSED,
                              STATUS_TEXT, UNLIMITED, Workspace)
from .parallel import Coordinator
from .branching import branch_start, spins_needed
from .tasks import initial_state, point_tasks, task_list

EXIT_INTERRUPTED = 75   # checkpointed after a signal; continue with --resume (EX_TEMPFAIL)
EXIT_FAILED = 1         # some tasks failed (recorded in the catalog); the others finished


# work budget of a kernel call, in block-steps (chain.simulate): ~0.05 s at the ~200 ns per
# block-step of the adaptive methods (benchmarks/results/step_budget_*); then sized by time
FIRST_BUDGET = 250_000
MIN_BUDGET = 1_000


class Refused(RuntimeError):
    """The run was refused before any work (output exists, is in use, or cannot be written)."""


class SimulationError(RuntimeError):
    """A task that cannot go on; the message names the task and the event."""


class Trajectory:
    """One task's chain between events: its workspace, clock and event counter."""

    def __init__(self, cfg, task, checkpoint=None, integrator=None, label=None, discarded=None):
        self.cfg = cfg
        self.task = task
        self.label = f"task {task.index}" if label is None else label     # in error messages
        self.discarded = cfg.run.discarded if discarded is None else discarded
        self.integrator = cfg.integrator if integrator is None else integrator
        self.ws = Workspace(task.model.N)
        # a chain that can creep keeps its creep phase's state in its checkpoints (store/checkpoint.py)
        self.creeps = carries_creep(task.model)
        if checkpoint is None:
            self.ws.load(*initial_state(cfg, task))
            self.clock = np.zeros(2)
            self.done = 0      # rows completed (events and creep episodes), transient included
        else:
            self.ws.load(checkpoint.force, checkpoint.psi, checkpoint.since, creep=checkpoint.creep)
            self.clock = checkpoint.clock.copy()
            self.done = checkpoint.done
        self.params = kernel_params(task.model, self.integrator)

    def checkpoint(self):
        """The state after the last completed event (also while an event is paused; the creep state is
        that of the same moment, Workspace.creep_state)."""
        force, psi, since, clock = self.ws.between_events(self.clock)
        return Checkpoint(force, psi, since, clock, self.done, self.ws.creep_state() if self.creeps else None)

    def state(self):
        """(force, psi) of every block now (between events), c-free frame."""
        return self.ws.state(self.clock, self.params)

    def advance(self, n, budget=UNLIMITED):
        """Run n events; returns (onset times, epicenters, diagnostics rows).

        With a work `budget` (chain.simulate) fewer events may be returned: the call stops
        when the budget is spent, possibly in the middle of an event, which the next call continues.
        """
        t = np.empty(n)
        epicenter = np.empty(n, dtype=np.int64)
        diag = np.empty((n, NDIAG))
        ws = self.ws
        status, k = simulate(ws.arrays, self.clock, self.params, n, budget, t, epicenter, diag)
        if status not in (OK, PAUSED):
            where = self.done + k
            phase = "transient " if where < self.discarded else ""
            raise SimulationError(f"{self.label} {phase}event {where}: {STATUS_TEXT[status]} "
                                  f"(method={self.integrator.method}, dt={self.integrator.dt}, "
                                  f"rtol={self.integrator.rtol})")
        self.done += k
        return t[:k], epicenter[:k], diag[:k]


def event_rows(task, t, epicenter, diag):
    """Kernel output -> catalog columns (EVENT_FIELDS, ensemble/store/schema.py)."""
    first = diag[:, D_FIRST].astype(np.int64)
    last = diag[:, D_LAST].astype(np.int64)
    return {
        "task": np.full(len(t), task.index, dtype=np.int64), "t": t, "epicenter": epicenter,
        "mu": np.log10(diag[:, D_SLIP]), "slip": diag[:, D_SLIP], "first": first, "last": last,
        "n_slipped": diag[:, D_NSLIP].astype(np.int64),
        "boundary": (first == 0) | (last == task.model.N - 1), "duration": diag[:, D_DURATION],
        "kind": diag[:, D_KIND].astype(np.int8), "ending": diag[:, D_ENDING].astype(np.int8),
    }


def integrator_text(integrator):
    """A task's [integrator] as TOML text (stored per task in the catalog)."""
    return "\n".join(section_lines(integrator))


def parse_integrator(text, where):
    """The inverse of integrator_text, validated like a config."""
    try:
        return from_dict({"integrator": tomllib.loads(text)}).integrator
    except (tomllib.TOMLDecodeError, ConfigError) as err:
        raise CatalogError(f"{where}: stored integrator cannot be read ({err})") from None


class Progress:
    """Rank 0's progress: a line at a steady interval (fit for a log file), fresher in the lock file."""

    LOCK_SECONDS = 2.0

    def __init__(self, coord, n_tasks, total_events, every, log, lock=None):
        self.coord, self.n_tasks, self.total, self.every, self.log = coord, n_tasks, total_events, every, log
        self.lock = lock
        self.start = time.perf_counter()
        self.last = self.start
        self.last_lock = -np.inf

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


class TaskRunner:
    """Integrates one task on this rank: kernel calls, buffer, flushes with checkpoints.

    A task that fails numerically (SimulationError) is recorded as failed in the
    catalog and the rank goes on with the next task; `failed` lists them.
    `rerun`: an [integrator] for tasks that failed before (rerun from their start), or None.
    """

    def __init__(self, cfg, writer, coord, progress, rerun=None):
        self.cfg, self.writer, self.coord, self.progress = cfg, writer, coord, progress
        self.rerun = rerun
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
            return Trajectory(cfg, task, self._start(task)), 0
        if rec.status == FAILED:
            if self.rerun is None or (cfg.run.branch and task.point not in self.spun):
                self.failed.append((task.index, rec.error))
                return None
            rec = self.writer.record(task.index, restart=True)
            self.writer.start(task.index, integrator_text(self.rerun))
            return Trajectory(cfg, task, self._start(task), self.rerun), 0
        if rec.checkpoint is not None:
            self.coord.count_events(rec.checkpoint.done, resumed=True)
        if rec.written >= cfg.run.events:
            if rec.status != FINISHED:   # stopped between its last commit and the finish record
                self.writer.finish(task.index, {})
            return None
        checkpoint = rec.checkpoint if rec.checkpoint is not None else self._start(task)
        return Trajectory(cfg, task, checkpoint, parse_integrator(rec.integrator, where)), rec.written

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
        chunk = 4
        budget = FIRST_BUDGET
        last_flush = time.perf_counter()
        record_time = 0.0
        recorded_here = 0

        def flush():
            nonlocal buffer, buffered, written, last_flush
            start = time.perf_counter()
            batch = ({name: np.concatenate([b[name] for b in buffer]) for name in buffer[0]}
                     if buffer else None)
            self.writer.commit(record, written, batch, traj.checkpoint())
            written += buffered
            buffer, buffered = [], 0
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
            now = time.perf_counter()
            if buffered >= cfg.output.batch or now - last_flush >= cfg.output.flush_seconds:
                flush()
            self.progress.maybe_print()
        flush()
        return recorded_here / max(record_time, 1e-9)


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


def _check_output(path, inputs):
    """Refuse, before the lock and any work, an output that cannot become a catalog (checks.output):
    a name that is not UTF-8, one of the run's inputs (its config), a directory, a missing or read-only
    folder. Whether the catalog exists is _prepare's to judge (--resume, --force)."""
    try:
        for p in (str(path), partial_path(path)):
            checks.output(p, inputs=inputs, force=True, what="catalog")
    except checks.UsageError as err:
        raise Refused(str(err)) from None


def _prepare(cfg, path, resume, force, rerun=None):
    """Rank 0's decision about the files (under the run's lock); returns (mode, message, spin-ups
    to run) or raises.

    rerun: the failed tasks are to be rerun with this [integrator] (which may differ from the stored one).
    """
    final, partial = str(path), partial_path(path)
    if resume:
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
        kept = (f"resuming {partial}: keeps {int(tasks['events_written'].sum())} of {len(tasks['point']) * cfg.run.events} "
                f"events recorded, {int(np.sum(tasks['status'] == FINISHED))} of {len(tasks['point'])} tasks finished"
                + (f", {int(np.sum(tasks['status'] == FAILED))} failed" if np.any(tasks["status"] == FAILED) else ""))
        return "resume", kept, spins_needed(cfg, task_list(cfg), tasks, rerun)
    if os.path.exists(final) and not force:
        raise Refused(f"{final}: catalog exists (use --force to overwrite it)")
    for p in (final, partial):
        kind = filekind.identify(p)[0]
        if force and kind not in ("missing", "catalog", "damaged", "empty"):
            # (a config, a summary or any other file given as -o is never replaced)
            raise Refused(f"{p} {filekind.describe(p)}; --force replaces only an event catalog")
    if os.path.exists(partial) and not force:
        raise Refused(f"{partial}: an interrupted run exists (use --resume to continue it, "
                      f"--force to start over)")
    tasks = task_list(cfg)
    _fits(partial, lambda: space.check_fits(partial, estimate_bytes(cfg, tasks)))
    return "new", None, spins_needed(cfg, tasks)


def _fits(partial, check):
    """Run a space check (space.py) before any HDF5 call; a catalog that does not fit is refused on every rank alike."""
    try:
        check()
    except OSError as err:
        raise CatalogError(f"{partial}: the catalog does not fit ({err.strerror or err})", collective=True) from None


def _kernels_cached():
    """True if the event kernels' compiled code is in numba's cache (see ensemble.model)."""
    import numba
    return bool(glob.glob(os.path.join(numba.config.CACHE_DIR, "**", "chain.simulate-*.nbi"), recursive=True))


def _compile_kernels(cfg, task, coord, say):
    """Compile (or load from the cache) the kernels before any timing starts.

    A signal in the meantime is acknowledged at once (Coordinator) and served when this returns.
    """
    cached = _kernels_cached()
    start = time.perf_counter()
    tiny = type(task)(task.index, task.point, task.seed_index, type(task.model)(**{**vars(task.model), "N": 2}))
    with coord.acknowledging("compiling kernels"):
        if not cached:
            say("compiling kernels (first run only, about a minute; cached for the next runs)")
        Trajectory(cfg, tiny).advance(0)
    if not cached:
        say(f"kernels ready in {time.perf_counter() - start:.0f} s")


def run(cfg, path, comm, resume=False, force=False, log=print, rerun=None, command="", inputs=()):
    """Run every task of cfg on the ranks of comm into the catalog at `path`.

    Rank 0 holds the run's lock (lock.py) from before anything is decided until
    the end. Writes to path + '.partial' and renames it to `path` when every task
    has finished, so a good catalog is never replaced by a half-written one.
    `rerun`: an [integrator] for the tasks that failed before (resume only).
    `inputs`: the run's input files (its config), which the output must not be.
    Returns 0, EXIT_INTERRUPTED after a stop request (every rank checkpointed),
    or EXIT_FAILED if some tasks failed (the others finished; the catalog stays partial).
    """
    rank = comm.Get_rank()
    say = log if rank == 0 else (lambda *a, **k: None)
    lock = None
    decision = None
    try:
        if rank == 0:
            try:
                _check_output(path, inputs)
                lock = RunLock(path, command).acquire()
                if lock.note:
                    say(f"note: {lock.note}")
                decision = _prepare(cfg, path, resume, force, rerun)
            except Exception as err:  # noqa: BLE001 - every rank raises it after the broadcast
                decision = err
        decision = comm.bcast(decision, root=0)
        if isinstance(decision, Exception):
            raise decision
        mode, message, spins = decision
        if mode == "complete":
            say(message)
            return 0
        if message:
            say(message)
        return _run_locked(cfg, path, comm, mode, spins, log, say, rerun, lock)
    finally:
        if lock is not None:
            lock.release()


def _run_locked(cfg, path, comm, mode, spins, log, say, rerun, lock):
    tasks = task_list(cfg)
    n_ranks = comm.Get_size()
    Writer = writers.choose_writer(cfg.output.writer, comm)
    partial = partial_path(path)
    for line in environment.stack():
        say(line)
    say(f"writing {partial} with {n_ranks} rank(s): {Writer.label(n_ranks)}")
    if spins:
        say(f"branching: {len(spins)} spin-up(s) of {cfg.run.transient} events first (counted among the tasks "
            f"of the progress line), then the tasks")
    t_start = time.perf_counter()
    if mode == "new":
        # rank 0's text on every rank: under mpio the catalog's attributes are written collectively
        software = comm.bcast(environment.software(Writer, n_ranks) if comm.Get_rank() == 0 else None, root=0)
        writer = Writer(partial, comm, cfg, tasks, integrator_text(cfg.integrator), software)
    else:
        writer = Writer(partial, comm)
    # event counts reach rank 0 as messages: about 100 per second in all, however many ranks
    coord = Coordinator(comm, report_seconds=min(max(1.0, comm.Get_size() / 100),
                                                  cfg.output.progress_seconds / 2))
    coord.install_signal_handlers()
    progress = Progress(coord, len(spins) + len(tasks),
                        len(spins) * cfg.run.transient + len(tasks) * (cfg.run.discarded + cfg.run.events),
                        cfg.output.progress_seconds, log, lock)
    worker = TaskRunner(cfg, writer, coord, progress, rerun)
    try:
        return _serve(cfg, path, comm, tasks, spins, writer, coord, progress, worker, log, t_start)
    finally:
        # until here a signal only sets a flag that nobody reads once the work is over
        coord.restore_signal_handlers()


def _serve(cfg, path, comm, tasks, spins, writer, coord, progress, worker, log, t_start):
    rank = comm.Get_rank()
    partial = partial_path(path)
    try:
        _compile_kernels(cfg, tasks[0], coord, log if rank == 0 else (lambda *a, **k: None))
        progress.restart_clock()
        busy, idle = _work(tasks, spins, worker, writer, coord, progress)
    except BaseException as err:
        # with more ranks the caller aborts them all; a broken file is not touched again
        if comm.Get_size() == 1 and not getattr(err, "broken", False):
            writer.close()
            coord.close()
        raise
    writer.close()   # first: rank 0 may still have to receive rows from the others
    # every rank counted its finished tasks before it could pass the collective close
    done = coord.tasks_done()
    stopped = done < len(spins) + len(tasks)
    coord.close()
    progress.maybe_print(tasks=done)
    per_rank = comm.gather((busy, idle, coord.rma_wait, worker.io_time), root=0)
    failed = sorted(f for part in comm.allgather(worker.failed) for f in part)
    elapsed = time.perf_counter() - t_start
    if rank == 0:
        for r, (b, i, w, io) in enumerate(per_rank):
            log(f"rank {r}: busy {b:.1f} s (of which {io:.2f} s writing, {w:.2f} s waiting for the "
                f"task counter), idle {i:.1f} s at the end")
        if stopped:
            log(f"interrupted ({coord.signal_name}): every rank checkpointed into {partial}; "
                f"continue with --resume")
        elif failed:
            log(f"failed: {len(failed)} of {len(tasks)} tasks (the others finished) in {partial}:")
            for k, message in failed:
                log(f"  task {k}: {message}")
            log(f"rerun them from their start with another integrator, e.g. `python -m ensemble resume "
                f"{path} --set integrator.dt=...` (or method, rtol)")
        else:
            os.replace(partial, str(path))
            log(f"wrote {path}: {len(tasks)} tasks, {len(tasks) * cfg.run.events} events in {elapsed:.1f} s")
    return EXIT_INTERRUPTED if stopped else (EXIT_FAILED if failed else 0)


def _work(tasks, spins, worker, writer, coord, progress):
    """Take work until none is left (or a stop request): first the spin-ups (run.branch), then, once
    all are done and their states known on every rank, the tasks. Returns (busy, idle) seconds.

    One counter numbers the work: items [0, len(spins)) are the spin-ups, then the tasks.
    """
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
        idle += _wait(first, writer, coord, progress)
        # one decision for all: a stop seen by some ranks only must not split the collective below
        if any(coord.comm.allgather(coord.poll())):
            return busy, idle
        for part in coord.comm.allgather(mine):
            for point, state in part.items():
                (worker.spun if isinstance(state, Checkpoint) else worker.spin_failed)[point] = state
        stopped = False
    while not stopped and k < total:
        t0 = time.perf_counter()
        stopped = not worker.run(tasks[k - first])
        busy += time.perf_counter() - t0
        if not stopped:
            k = coord.next_task()
    return busy, idle + _wait(total, writer, coord, progress)


def _wait(count, writer, coord, progress):
    """Keep serving MPI (and rank 0's writer) until `count` items are done or a stop is requested;
    returns the seconds waited."""
    waited = time.perf_counter()
    while not coord.poll() and coord.tasks_done() < count:
        writer.poll()
        progress.maybe_print()
        time.sleep(0.05)
    return time.perf_counter() - waited
