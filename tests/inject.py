"""Fault injection for tests: crash or fail a real run at a chosen point (used in a subprocess).

    python -c "from tests import inject; inject.crash_at_write(5); inject.main(['run', ...])"

Nothing here is imported by the package: the faults are injected by patching, from outside.
"""
import os
import signal
import sys
import time

import h5py

CRASH_CODE = 99


def _count_writes(on_write):
    """Call on_write(k, what) before the k-th dataset write or file flush of this process (1-based)."""
    counter = [0]
    set_item, flush = h5py.Dataset.__setitem__, h5py.File.flush

    def tick(what):
        counter[0] += 1
        on_write(counter[0], what)

    def patched_set(self, key, value):
        tick(f"write {self.name}")
        return set_item(self, key, value)

    def patched_flush(self):
        tick("flush")
        return flush(self)
    h5py.Dataset.__setitem__ = patched_set
    h5py.File.flush = patched_flush


def crash_at_write(k):
    """Die like kill -9 (no cleanup, nothing flushed) just before the k-th write or flush."""
    def on_write(i, what):
        if i == k:
            os._exit(CRASH_CODE)
    _count_writes(on_write)


def log_writes(path):
    """Append one line per write or flush ('k what') to `path`."""
    def on_write(i, what):
        with open(path, "a") as fh:
            fh.write(f"{i} {what}\n")
    _count_writes(on_write)


def before_finish(log):
    """The number of the last write or flush before the first finish record (a task's provenance, /tasks/rank)
    in a log of log_writes: a crash there leaves that task with every row committed and no finish recorded."""
    with open(log) as fh:
        return next(int(line.split()[0]) for line in fh if line.split()[1:] == ["write", "/tasks/rank"]) - 1


def fail_on_rank(rank, after_calls=1):
    """Raise a RuntimeError (a bug, not a numerical failure) on one MPI rank once it has run a while."""
    from mpi4py import MPI

    from ensemble.run import worker
    calls = [0]
    original = worker.event_rows

    def patched(*args):
        calls[0] += 1
        if MPI.COMM_WORLD.Get_rank() == rank and calls[0] > after_calls:
            raise RuntimeError("injected failure")
        return original(*args)
    worker.event_rows = patched


def _signal_self(signum):
    os.kill(os.getpid(), signum)
    signal.getsignal(signum)   # the handler runs between bytecodes: before this returns


def signal_at_write(signum, what="write /events/task", nth=1):
    """Send this process `signum` just before its `nth` write (or flush) named `what` (as log_writes
    names them; by default: the first batch of events, which is then committed before the run
    stops): an interruption at a known point of the run, however fast it is."""
    seen = [0]

    def on_write(i, name):
        if name == what:
            seen[0] += 1
            if seen[0] == nth:
                _signal_self(signum)
    _count_writes(on_write)


def signal_when_paused(signum):
    """Send this process `signum` when a kernel call first ends inside an event (the work budget
    spent) after the transient: the stop then checkpoints while an event is paused."""
    from ensemble.run import trajectory
    advance = trajectory.Trajectory.advance
    sent = [False]

    def patched(self, n, *args, **kwargs):
        out = advance(self, n, *args, **kwargs)
        if not sent[0] and len(out[0]) < n and self.done > self.cfg.run.transient:
            sent[0] = True
            _signal_self(signum)
        return out
    trajectory.Trajectory.advance = patched


def signal_when_creeping(signum, paused=False):
    """Send this process `signum` when a kernel call first ends with blocks creeping (a creep episode in
    flight; paused: and an event paused too) after the transient: the stop then checkpoints the creep state."""
    from ensemble.run import trajectory
    from ensemble.model.workspace import CS_NCREEP
    advance = trajectory.Trajectory.advance
    sent = [False]

    def patched(self, n, *args, **kwargs):
        out = advance(self, n, *args, **kwargs)
        if (not sent[0] and self.ws.cstate[CS_NCREEP] > 0 and self.done > self.cfg.run.transient
                and (self.ws.paused or not paused)):
            sent[0] = True
            _signal_self(signum)
        return out
    trajectory.Trajectory.advance = patched


def count_pauses(path, first_budget=None):
    """Write to `path`, at exit, how many kernel calls ended inside an event (the work budget spent).

    first_budget replaces worker.FIRST_BUDGET, the budget of a task's first call, so that a run
    whose events are all cheaper than the default (250k block-steps) pauses as well.
    """
    import atexit

    from ensemble.run import trajectory
    from ensemble.run import worker
    if first_budget is not None:
        worker.FIRST_BUDGET = first_budget
    advance = trajectory.Trajectory.advance
    paused = [0]

    def patched(self, n, *args, **kwargs):
        out = advance(self, n, *args, **kwargs)
        paused[0] += self.ws.paused
        return out
    trajectory.Trajectory.advance = patched

    def write():
        with open(path, "w") as fh:
            fh.write(f"{paused[0]}\n")
    atexit.register(write)


def hold(ready, go, rank=0, seconds=300):
    """Hold the run at its first kernel call (on MPI rank `rank`; the lock is taken, the catalog
    open) until the file `go` exists, after creating `ready`; a RuntimeError after `seconds`."""
    from ensemble.run import trajectory
    advance = trajectory.Trajectory.advance
    held = [False]

    def patched(self, *args, **kwargs):
        if not held[0]:
            held[0] = True
            from mpi4py import MPI
            if MPI.COMM_WORLD.Get_rank() == rank:
                open(ready, "w").close()
                deadline = time.monotonic() + seconds
                while not os.path.exists(go):
                    if time.monotonic() > deadline:
                        raise RuntimeError(f"held for {seconds} s: {go} never appeared")
                    time.sleep(0.05)
        return advance(self, *args, **kwargs)
    trajectory.Trajectory.advance = patched


def signal_after_rename(signum):
    """Send this process `signum` right after the run renames its finished catalog."""
    from ensemble.run import runner
    replace = os.replace

    def patched(src, dst):
        replace(src, dst)
        _signal_self(signum)
    runner.os.replace = patched


def signal_in_spin_up(signum, point, after_events):
    """Send this process `signum` once the spin-up of `point` has run `after_events` events."""
    from ensemble.run import trajectory
    advance = trajectory.Trajectory.advance
    sent = [False]

    def patched(self, *args, **kwargs):
        out = advance(self, *args, **kwargs)
        if not sent[0] and self.label == f"spin-up of point {point}" and self.done >= after_events:
            sent[0] = True
            _signal_self(signum)
        return out
    trajectory.Trajectory.advance = patched


def fail_spin_up(point, after_events=1):
    """Make the spin-up of `point` fail numerically once it has run `after_events` events."""
    from ensemble.run import trajectory
    advance = trajectory.Trajectory.advance

    def patched(self, *args, **kwargs):
        if self.label == f"spin-up of point {point}" and self.done >= after_events:
            raise trajectory.SimulationError(f"{self.label} event {self.done}: injected failure")
        return advance(self, *args, **kwargs)
    trajectory.Trajectory.advance = patched


def main(argv):
    from ensemble.cli import main as cli_main
    sys.exit(cli_main(argv))


def fail_in(rank, target, exception=RuntimeError):
    """Raise `exception("injected failure in TARGET")` on MPI rank `rank` (-1: any) when `target` ("module:Class.method"
    or "module:function", in the package) is called: a step of a collective path that fails on one rank."""
    import importlib

    from mpi4py import MPI
    module_name, attr = target.split(":")
    owner = importlib.import_module(module_name)
    *path, name = attr.split(".")
    for part in path:
        owner = getattr(owner, part)
    original = getattr(owner, name)

    def patched(*args, **kwargs):
        if rank in (-1, MPI.COMM_WORLD.Get_rank()):     # -1: whichever rank calls it
            raise exception(f"injected failure in {target}")
        return original(*args, **kwargs)
    setattr(owner, name, patched)
