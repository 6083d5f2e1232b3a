"""MPI plumbing of a run: the shared task counter, progress counts, stop requests.

Work distribution: an MPI one-sided fetch-and-add on a counter that lives on
rank 0 (no master rank: rank 0 computes too). Without an asynchronous progress
engine such a request waits until rank 0 next calls MPI (measured here: MPICH
ch4/ucx, even on one node), so every rank calls `poll` between kernel calls,
which are sized to last about `run.poll_seconds`. One-sided operations happen
once per task (take a task, count it done), so that wait is paid once per task,
not per kernel call; the run-wide event counts for the progress line travel as
non-blocking messages instead.
"""
import contextlib
import os
import signal
import threading
import time

import numpy as np
from mpi4py import MPI

NEXT_TASK, TASKS_DONE = range(2)      # counters in the window on rank 0
STOP_TAG, COUNT_TAG = 23, 24
INTERRUPT_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1)


class Coordinator:
    """Task counter, progress counts and stop requests shared by all ranks."""

    def __init__(self, comm, report_seconds=1.0):
        self.comm = comm
        self.rank = comm.Get_rank()
        self.size = comm.Get_size()
        itemsize = np.dtype(np.int64).itemsize
        self.win = MPI.Win.Allocate(2 * itemsize if self.rank == 0 else 0, itemsize, comm=comm)
        if self.rank == 0:
            self.win.Lock(0, MPI.LOCK_EXCLUSIVE)
            np.frombuffer(self.win.tomemory(), dtype=np.int64)[:] = 0
            self.win.Unlock(0)
        comm.Barrier()
        self.stop_requested = False
        self.signal_name = None
        self._local_signal = None
        self._old_handlers = {}

        self._sent = {tag: np.zeros(self.size, dtype=np.int64) for tag in (STOP_TAG, COUNT_TAG)}
        self._received = {tag: np.zeros(self.size, dtype=np.int64) for tag in (STOP_TAG, COUNT_TAG)}
        self._requests = []
        self.report_seconds = report_seconds
        self._unreported = [0, 0]
        self._last_report = time.perf_counter()
        self.rma_wait = 0.0      # seconds spent in one-sided operations on the counters
        self.events_total = 0    # on rank 0: events done on all ranks (as reported so far)
        self.events_resumed = 0  # ... of which done before a resume

    # -- one-sided counters -------------------------------------------------------------

    def _fetch_add(self, which, amount):
        start = time.perf_counter()
        one = np.array([amount], dtype=np.int64)
        old = np.zeros(1, dtype=np.int64)
        self.win.Lock(0, MPI.LOCK_SHARED)
        self.win.Fetch_and_op(one, old, 0, which, MPI.SUM)
        self.win.Unlock(0)
        self.rma_wait += time.perf_counter() - start
        return int(old[0])

    def next_task(self):
        """Index of the next task nobody has taken (may be >= the number of tasks)."""
        return self._fetch_add(NEXT_TASK, 1)

    def task_done(self):
        self._fetch_add(TASKS_DONE, 1)

    def tasks_done(self):
        """Tasks finished on all ranks."""
        out = np.zeros(2, dtype=np.int64)
        self.win.Lock(0, MPI.LOCK_SHARED)
        self.win.Get(out, 0)
        self.win.Unlock(0)
        return int(out[TASKS_DONE])

    # -- messages -----------------------------------------------------------------------

    def _send(self, tag, obj, dest):
        self._requests.append(self.comm.isend(obj, dest=dest, tag=tag))
        self._sent[tag][dest] += 1

    def _receive(self, tag, source):
        obj = self.comm.recv(source=source, tag=tag)
        self._received[tag][source] += 1
        if tag == STOP_TAG and not self.stop_requested:
            self.stop_requested = True
            self.signal_name = obj
        elif tag == COUNT_TAG:
            self.events_total += obj[0]
            self.events_resumed += obj[1]

    def _drain(self, tag):
        status = MPI.Status()
        while self.comm.Iprobe(source=MPI.ANY_SOURCE, tag=tag, status=status):
            self._receive(tag, status.Get_source())

    def count_events(self, n, resumed=False, force=False):
        """Add n events to the run-wide count (sent to rank 0 now and then).

        resumed: events done by an earlier, interrupted run (not counted in the rate).
        """
        self._unreported[1 if resumed else 0] += n
        now = time.perf_counter()
        if any(self._unreported) and (force or now - self._last_report >= self.report_seconds):
            if self.rank == 0:
                self.events_total += self._unreported[0] + self._unreported[1]
                self.events_resumed += self._unreported[1]
            else:
                self._send(COUNT_TAG, (self._unreported[0] + self._unreported[1], self._unreported[1]), 0)
            self._unreported = [0, 0]
            self._last_report = now

    # -- stop requests (signals) --------------------------------------------------------

    def install_signal_handlers(self):
        for sig in INTERRUPT_SIGNALS:
            self._old_handlers[sig] = signal.signal(sig, self._on_signal)

    def restore_signal_handlers(self):
        for sig, handler in self._old_handlers.items():
            signal.signal(sig, handler)

    def _on_signal(self, signum, frame):
        self._local_signal = signal.Signals(signum).name

    @contextlib.contextmanager
    def acknowledging(self, what):
        """Say at once that a signal arrived during `what` (which cannot be interrupted).

        Python runs signal handlers only between bytecodes of the main thread, which a
        long call into compiled code (LLVM compiling the kernels) delays. The C-level
        handler also writes the signal number to a wakeup fd at once; a thread waiting on
        it says so (it gets the interpreter while the main thread is in such a call).
        """
        read_fd, write_fd = os.pipe()
        os.set_blocking(write_fd, False)
        old = signal.set_wakeup_fd(write_fd)
        done = threading.Event()

        def watch():
            while True:
                data = os.read(read_fd, 1)
                if done.is_set() or not data:
                    return
                if data[0] in INTERRUPT_SIGNALS:
                    os.write(2, f"rank {self.rank}: {signal.Signals(data[0]).name} received while {what}; "
                                f"the run stops as soon as that is done\n".encode())
        thread = threading.Thread(target=watch, name="signal-ack", daemon=True)
        thread.start()
        try:
            yield
        finally:
            signal.set_wakeup_fd(old)
            done.set()
            os.write(write_fd, b"\0")
            thread.join()
            os.close(read_fd)
            os.close(write_fd)

    def poll(self):
        """Make MPI progress; True once a stop was requested here or on any other rank."""
        if self._local_signal and not self.stop_requested:
            # Tell every other rank: a signal may reach only one of them.
            self.stop_requested = True
            self.signal_name = self._local_signal
            for r in range(self.size):
                if r != self.rank:
                    self._send(STOP_TAG, self.signal_name, r)
        self._drain(STOP_TAG)
        if self.rank == 0:
            self._drain(COUNT_TAG)
        return self.stop_requested

    def close(self):
        """Collective: receive every message still in flight, then free the window."""
        self.count_events(0, force=True)
        for tag in (STOP_TAG, COUNT_TAG):
            expected = np.zeros(self.size, dtype=np.int64)
            self.comm.Alltoall(self._sent[tag], expected)
            for source in range(self.size):
                while self._received[tag][source] < expected[source]:
                    self._receive(tag, source)
        MPI.Request.Waitall(self._requests)
        self.comm.Barrier()
        self.win.Free()
