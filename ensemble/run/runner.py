"""A run on every rank: decide, open the catalog, serve the work (worker.py) until none is left, close, rename.

The same code runs serially (one rank, no mpirun) and under MPI. Each task is one trajectory on one
rank (worker.py); its seed comes from its index, so results do not depend on the number of ranks or
on which rank ran a task. Every step takes the run's context (context.py).
"""
import os
import time

from .. import environment
from ..compiled import announced
from ..model.workspace import KIND_CREEP
from ..store import reader, writers
from ..sweep import task_list
from .decision import check_output, prepare
from .lock import RunLock
from .parallel import Coordinator
from .progress import Progress
from .trajectory import Trajectory, integrator_text
from .worker import TaskRunner, work

EXIT_INTERRUPTED = 75   # checkpointed after a signal; continue with --resume (EX_TEMPFAIL)
EXIT_FAILED = 1         # some tasks failed (recorded in the catalog); the others finished


def run(ctx):
    """Run every task of ctx.cfg on the ranks of ctx.comm into the catalog at ctx.path.

    Rank 0 holds the run's lock (lock.py) from before anything is decided until
    the end. Writes to the partial name and renames it to ctx.path when every task
    has finished, so a good catalog is never replaced by a half-written one.
    ctx.rerun: an [integrator] for the tasks that failed before (resume only).
    ctx.inputs: the run's input files (its config), which the output must not be.
    Returns 0, EXIT_INTERRUPTED after a stop request (every rank checkpointed),
    or EXIT_FAILED if some tasks failed (the others finished; the catalog stays partial).
    """
    lock = None
    decision = None
    try:
        if ctx.rank == 0:
            try:
                check_output(ctx)
                lock = RunLock(ctx.path, ctx.command).acquire()
                if lock.note:
                    ctx.say(f"note: {lock.note}")
                decision = prepare(ctx)
            except Exception as err:  # noqa: BLE001 - every rank raises it after the broadcast
                decision = err
        decision = ctx.comm.bcast(decision, root=0)
        if isinstance(decision, Exception):
            raise decision
        mode, message, spins = decision
        if mode == "complete":
            ctx.say(message)
            return 0
        if message:
            ctx.say(message)
        return _run_locked(ctx.with_(lock=lock), mode, spins)
    finally:
        if lock is not None:
            lock.release()


def _run_locked(ctx, mode, spins):
    """Open (or create) the catalog and the task counter, then serve the work (_serve)."""
    cfg, comm, say = ctx.cfg, ctx.comm, ctx.say
    tasks = task_list(cfg)
    Writer = writers.choose_writer(cfg.output.writer, comm)
    for line in environment.stack():
        say(line)
    say(f"writing {ctx.partial} with {ctx.n_ranks} rank(s): {Writer.label(ctx.n_ranks)}")
    if spins:
        say(f"branching: {len(spins)} spin-up(s) of {cfg.run.transient} events first (counted among the tasks "
            f"of the progress line), then the tasks")
    t_start = time.perf_counter()
    if mode == "new":
        # rank 0's text on every rank: under mpio the catalog's attributes are written collectively
        software = comm.bcast(environment.software(Writer, ctx.n_ranks) if ctx.rank == 0 else None, root=0)
        writer = Writer(ctx.partial, comm, cfg, tasks, integrator_text(cfg.integrator), software)
    else:
        writer = Writer(ctx.partial, comm)
    # event counts reach rank 0 as messages: about 100 per second in all, however many ranks
    coord = Coordinator(comm, report_seconds=min(max(1.0, ctx.n_ranks / 100), cfg.output.progress_seconds / 2))
    coord.install_signal_handlers()
    ctx = ctx.with_(writer=writer, coord=coord, progress=Progress.of_run(ctx, coord, tasks, spins))
    try:
        return _serve(ctx, tasks, spins, t_start)
    finally:
        # until here a signal only sets a flag that nobody reads once the work is over
        coord.restore_signal_handlers()


def _serve(ctx, tasks, spins, t_start):
    """Compile the kernels, do this rank's share of the work, close the catalog collectively and
    (rank 0) report, then rename the finished catalog to its final name."""
    writer, coord, progress, log = ctx.writer, ctx.coord, ctx.progress, ctx.say
    worker = TaskRunner(ctx)
    try:
        _compile_kernels(ctx, tasks[0])
        progress.restart_clock()
        busy, idle = work(ctx, tasks, spins, worker)
    except BaseException as err:
        # with more ranks the caller aborts them all; a broken file is not touched again
        if ctx.n_ranks == 1 and not getattr(err, "broken", False):
            writer.close()
            coord.close()
        raise
    writer.close()   # first: rank 0 may still have to receive rows from the others
    # every rank counted its finished tasks before it could pass the collective close
    done = coord.tasks_done()
    stopped = done < len(spins) + len(tasks)
    coord.close()
    progress.maybe_print(tasks=done)
    per_rank = ctx.comm.gather((busy, idle, coord.rma_wait, worker.io_time), root=0)
    failed = sorted(f for part in ctx.comm.allgather(worker.failed) for f in part)
    elapsed = time.perf_counter() - t_start
    if ctx.rank == 0:
        for r, (b, i, w, io) in enumerate(per_rank):
            log(f"rank {r}: busy {b:.1f} s (of which {io:.2f} s writing, {w:.2f} s waiting for the "
                f"task counter), idle {i:.1f} s at the end")
        if stopped:
            log(f"interrupted ({coord.signal_name}): every rank checkpointed into {ctx.partial}; "
                f"continue with --resume")
        elif failed:
            log(f"failed: {len(failed)} of {len(tasks)} tasks (the others finished) in {ctx.partial}:")
            for k, message in failed:
                log(f"  task {k}: {message}")
            log(f"rerun them from their start with another integrator, e.g. `python -m ensemble resume "
                f"{ctx.path} --set integrator.dt=...` (or method, rtol, creep_tol)")
        else:
            os.replace(ctx.partial, ctx.path)
            log(f"wrote {ctx.path}: {len(tasks)} tasks, {_rows_text(ctx.path)} in {elapsed:.1f} s")
    return EXIT_INTERRUPTED if stopped else (EXIT_FAILED if failed else 0)


def _rows_text(path):
    """"6000 rows: 1100 inertial events, 4900 creep episodes" of a finished catalog (run.events counts both kinds),
    or "6000 events" where every row is an inertial event."""
    with reader.Reader(path) as r:
        n_tasks = len(r.tasks["events_written"])
        rows = int(r.tasks["events_written"].sum())
        creep = sum(r.count(k, KIND_CREEP) for k in range(n_tasks))
    if not creep:
        return f"{rows} events"
    return f"{rows} rows: {rows - creep} inertial events, {creep} creep episodes"


def _compile_kernels(ctx, task):
    """Compile (or load from the cache) the kernels before any timing starts, saying so if they compile.

    A signal in the meantime is acknowledged at once (Coordinator) and served when this returns.
    """
    tiny = type(task)(task.index, task.point, task.seed_index, type(task.model)(**{**vars(task.model), "N": 2}))
    with ctx.coord.acknowledging("compiling kernels"), announced(ctx.say, task.model.law):
        Trajectory(ctx.cfg, tiny).advance(0)
