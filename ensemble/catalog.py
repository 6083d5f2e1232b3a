"""The HDF5 event catalog: schema, checkpoints, writers and reader.

This is the only module that touches HDF5 under MPI. Every task records
exactly `run.events` events, so the whole catalog is laid out (and allocated)
when the file is created, collectively: task k owns rows
[k * events, (k + 1) * events) of every dataset in /events and its own slice of
/checkpoint. After creation nothing structural changes (no resize, no new
objects, no attribute writes), so each rank writes its own task's rows with
independent writes and nothing collective is left in the hot path; a process
killed at any moment leaves a file whose metadata is intact.

    /events/task        int64    task index
    /events/t           float64  onset time of the event
    /events/epicenter   int64    first block to slide (0-based)
    /events/mu          float64  magnitude log10(slip)
    /events/slip        float64  sum of the slips of all blocks
    /events/first       int64    lowest block that slipped
    /events/last        int64    highest block that slipped
    /events/n_slipped   int64    number of blocks that slipped
    /events/boundary    bool     rupture reached block 0 or N-1
    /events/duration    float64  time from onset until all blocks are at rest
    /tasks/{point, seed_index, N, l, nu, a, b, c}    one row per task
    /tasks/events_written   events of the task stored so far
    /tasks/{rank, wall_time, events_per_second, seed_entropy, spawn_key}   provenance
    /checkpoint/state   float64  per task two slots of [force (N), psi (N), since (2N), clock (2)]:
                                 block i's force and psi hold at the two-float time
                                 since[i] = (since[2i], since[2i+1]); clock = (hi, lo) now
    /checkpoint/offset  int64    start of each task's slots in /checkpoint/state
    /checkpoint/commit  int64    per task [slot in use, events done incl. transient, events written]
    attributes of /: config (resolved TOML text), version, format

A checkpoint is written into the slot not in use, after the events it covers;
only then the commit row switches to it. A crash between the two leaves the
previous (slot, counters) pair, which is still complete and consistent.
"""
import os

import h5py
import numpy as np

from . import __version__

FORMAT = "bk-catalog-2"

EVENT_FIELDS = {
    "task": np.int64, "t": np.float64, "epicenter": np.int64, "mu": np.float64,
    "slip": np.float64, "first": np.int64, "last": np.int64, "n_slipped": np.int64,
    "boundary": np.bool_, "duration": np.float64,
}
TASK_FIELDS = {
    "point": np.int64, "seed_index": np.int64, "N": np.int64, "l": np.float64,
    "nu": np.float64, "a": np.float64, "b": np.float64, "c": np.float64,
}
PROVENANCE_FIELDS = {
    "rank": np.int64, "wall_time": np.float64, "events_per_second": np.float64,
    "seed_entropy": np.int64, "spawn_key": np.int64,
}
_FILL = {np.int64: -1, np.float64: np.nan, np.bool_: False}
COMMIT_SLOT, COMMIT_DONE, COMMIT_WRITTEN = range(3)


class CatalogError(RuntimeError):
    """A catalog that cannot be created, written or read; the message names the file."""


def partial_path(path):
    """Where a run writes until every task has finished (then renamed to `path`)."""
    return str(path) + ".partial"


def has_parallel_hdf5():
    return bool(h5py.get_config().mpi)


def _state_size(n):
    return 4 * n + 2


class Checkpoint:
    """A task's between-events state: forces, psi, their times (N x 2), compensated clock, events done."""

    def __init__(self, force, psi, since, clock, done):
        self.force, self.psi, self.since, self.clock, self.done = force, psi, since, clock, done

    def pack(self):
        return np.concatenate([self.force, self.psi, self.since.ravel(), self.clock])

    @classmethod
    def unpack(cls, flat, done):
        n = (len(flat) - 2) // 4
        return cls(flat[:n].copy(), flat[n:2 * n].copy(), flat[2 * n:4 * n].reshape(n, 2).copy(),
                   flat[4 * n:].copy(), int(done))


class _Layout:
    """Structure of a catalog file, created collectively and opened once."""

    def __init__(self, h5):
        self.h5 = h5
        self.events = {name: h5["events"][name] for name in EVENT_FIELDS}
        self.tasks = {name: h5["tasks"][name] for name in h5["tasks"]}
        self.state = h5["checkpoint"]["state"]
        self.offset = h5["checkpoint"]["offset"][...]
        self.commit = h5["checkpoint"]["commit"]
        self.per_task = self.events["t"].shape[0] // max(len(self.offset), 1)

    @staticmethod
    def create(h5, cfg, tasks):
        """Every dataset and attribute of the catalog (call on every rank with the same values)."""
        rows = len(tasks) * cfg.run.events
        h5.attrs["config"] = cfg.to_toml()
        h5.attrs["version"] = __version__
        h5.attrs["format"] = FORMAT
        ev = h5.create_group("events")
        for name, dtype in EVENT_FIELDS.items():
            # never fill: a full run would otherwise write the whole catalog twice; rows past
            # /tasks/events_written are undefined and never read
            ev.create_dataset(name, shape=(rows,), dtype=dtype, fillvalue=_FILL[dtype], fill_time="never")
        tg = h5.create_group("tasks")
        for name, dtype in TASK_FIELDS.items():
            values = [getattr(t.model, name) if name in ("N", "l", "nu", "a", "b", "c")
                      else getattr(t, name) for t in tasks]
            tg.create_dataset(name, data=np.asarray(values, dtype=dtype))
        tg.create_dataset("events_written", data=np.zeros(len(tasks), dtype=np.int64))
        for name, dtype in PROVENANCE_FIELDS.items():
            tg.create_dataset(name, shape=(len(tasks),), dtype=dtype, fillvalue=_FILL[dtype])
        sizes = np.array([2 * _state_size(t.model.N) for t in tasks], dtype=np.int64)
        offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        cp = h5.create_group("checkpoint")
        cp.create_dataset("state", shape=(int(sizes.sum()),), dtype=np.float64, fillvalue=np.nan)
        cp.create_dataset("offset", data=offset)
        cp.create_dataset("commit", data=np.tile(np.array([-1, 0, 0], dtype=np.int64), (len(tasks), 1)))

    def write_events(self, task, start, batch):
        n = len(batch["t"])
        if start + n > self.per_task:
            raise CatalogError(f"{self.h5.filename}: task {task} has more than {self.per_task} events")
        lo = task * self.per_task + start
        for name in EVENT_FIELDS:
            self.events[name][lo:lo + n] = batch[name]

    def write_checkpoint(self, task, checkpoint, written):
        slot = 1 - int(self.commit[task, COMMIT_SLOT]) if self.commit[task, COMMIT_SLOT] >= 0 else 0
        flat = checkpoint.pack()
        lo = self.offset[task] + slot * len(flat)
        self.state[lo:lo + len(flat)] = flat
        self.commit[task] = np.array([slot, checkpoint.done, written], dtype=np.int64)
        self.tasks["events_written"][task] = written

    def read_checkpoint(self, task, n):
        slot, done, written = (int(x) for x in self.commit[task])
        if slot < 0:
            return None, 0
        size = _state_size(n)
        lo = self.offset[task] + slot * size
        return Checkpoint.unpack(self.state[lo:lo + size], done), written

    def write_provenance(self, task, values):
        for name, value in values.items():
            self.tasks[name][task] = value


class _Writer:
    """Common API of the writers: commit(task, start, batch, checkpoint), finish(task, provenance)."""

    def resume_point(self, task, n):
        """(Checkpoint or None, events written) of a task in this catalog."""
        return self.layout.read_checkpoint(task, n)


class ParallelWriter(_Writer):
    """All ranks open one file with the mpio driver; each writes its own tasks independently."""

    name = "parallel HDF5 (mpio), independent writes"

    def __init__(self, path, comm, cfg=None, tasks=None):
        self.comm = comm
        mode = "w" if cfg is not None else "r+"
        try:
            self.h5 = h5py.File(path, mode, driver="mpio", comm=comm)
        except OSError as err:
            raise CatalogError(f"{path}: cannot open catalog ({err})") from None
        if cfg is not None:
            _Layout.create(self.h5, cfg, tasks)
            self.h5.flush()
        self.layout = _Layout(self.h5)

    def commit(self, task, start, batch, checkpoint):
        if batch is not None:
            self.layout.write_events(task, start, batch)
        self.layout.write_checkpoint(task, checkpoint, start + (0 if batch is None else len(batch["t"])))

    def finish(self, task, provenance):
        self.layout.write_provenance(task, provenance)

    def poll(self):
        pass

    def close(self):
        """Collective."""
        self.layout = None
        self.h5.close()


class Rank0Writer(_Writer):
    """Rank 0 owns the file; other ranks send their rows to it (no parallel HDF5 needed).

    Rank 0 writes incoming rows whenever it polls (between kernel calls) and,
    at the end, until every rank has said it is done. With one rank this is a
    plain serial writer.
    """

    name = "serial HDF5 on rank 0, rows sent by message"
    TAG = 17

    def __init__(self, path, comm, cfg=None, tasks=None):
        self.comm = comm
        self.rank = comm.Get_rank()
        self.layout = None
        error = None
        if self.rank == 0:
            try:
                self.h5 = h5py.File(path, "w" if cfg is not None else "r+")
                if cfg is not None:
                    _Layout.create(self.h5, cfg, tasks)
                    self.h5.flush()
                self.layout = _Layout(self.h5)
            except OSError as err:
                error = f"{path}: cannot open catalog ({err})"
        error = comm.bcast(error, root=0)
        if error:
            raise CatalogError(error)

    def resume_point(self, task, n):
        # Only rank 0 can read the file: ask it (it answers while polling).
        if self.rank == 0:
            return self.layout.read_checkpoint(task, n)
        self.comm.send(("read", task, n), dest=0, tag=self.TAG)
        return self.comm.recv(source=0, tag=self.TAG + 1)

    def commit(self, task, start, batch, checkpoint):
        if self.rank == 0:
            self._commit(task, start, batch, checkpoint)
        else:
            self.comm.send(("commit", task, start, batch, checkpoint), dest=0, tag=self.TAG)

    def finish(self, task, provenance):
        if self.rank == 0:
            self.layout.write_provenance(task, provenance)
            self.h5.flush()
        else:
            self.comm.send(("finish", task, provenance), dest=0, tag=self.TAG)

    def _commit(self, task, start, batch, checkpoint):
        if batch is not None:
            self.layout.write_events(task, start, batch)
        self.h5.flush()   # events reach the file before the commit row points past them
        self.layout.write_checkpoint(task, checkpoint, start + (0 if batch is None else len(batch["t"])))
        self.h5.flush()

    def _serve(self, status):
        """Carry out one request of another rank; returns its kind."""
        msg = self.comm.recv(source=status.Get_source(), tag=self.TAG)
        kind = msg[0]
        if kind == "commit":
            self._commit(*msg[1:])
        elif kind == "finish":
            self.layout.write_provenance(msg[1], msg[2])
            self.h5.flush()
        elif kind == "read":
            self.comm.send(self.layout.read_checkpoint(msg[1], msg[2]), dest=status.Get_source(),
                           tag=self.TAG + 1)
        return kind

    def poll(self):
        if self.rank != 0:
            return
        from mpi4py import MPI
        status = MPI.Status()
        while self.comm.Iprobe(source=MPI.ANY_SOURCE, tag=self.TAG, status=status):
            self._serve(status)

    def close(self):
        """Collective: rank 0 serves every other rank until each has sent 'done'."""
        from mpi4py import MPI
        if self.rank == 0:
            waiting = self.comm.Get_size() - 1
            status = MPI.Status()
            while waiting:
                self.comm.Probe(source=MPI.ANY_SOURCE, tag=self.TAG, status=status)
                if self._serve(status) == "done":
                    waiting -= 1
            self.layout = None
            self.h5.close()
        else:
            self.comm.send(("done",), dest=0, tag=self.TAG)
        self.comm.Barrier()


WRITERS = {"parallel": ParallelWriter, "rank0": Rank0Writer}


def choose_writer(name, comm):
    """'auto' -> parallel HDF5 when h5py has MPI support and there is more than one rank."""
    if name == "auto":
        name = "parallel" if comm.Get_size() > 1 and has_parallel_hdf5() else "rank0"
    if name == "parallel" and not has_parallel_hdf5():
        raise CatalogError("output.writer = 'parallel' needs h5py built with MPI support")
    return WRITERS[name]


def _open_for_reading(path):
    if not os.path.exists(path):
        raise CatalogError(f"{path}: no such catalog")
    try:
        h5 = h5py.File(path, "r")
    except OSError as err:
        raise CatalogError(f"{path}: cannot read catalog ({err})") from None
    found = h5.attrs.get("format")
    if found != FORMAT:
        h5.close()
        if isinstance(found, str) and found.startswith("bk-catalog-"):
            raise CatalogError(f"{path}: catalog format {found}, this version reads {FORMAT} "
                               "(the checkpoint layout changed; rerun, or read it with the older version)")
        raise CatalogError(f"{path}: not an event catalog of this package")
    return h5


def read_tasks(path):
    """Catalog -> (rows per task, tasks: dict of arrays, attrs: dict), without the events."""
    with _open_for_reading(path) as h5:
        layout = _Layout(h5)
        tasks = {name: ds[...] for name, ds in layout.tasks.items()}
        attrs = {k: h5.attrs[k] for k in h5.attrs}
        return layout.per_task, tasks, attrs


def read(path):
    """Catalog -> (events: dict of arrays with only the written rows, tasks: dict, attrs: dict)."""
    with _open_for_reading(path) as h5:
        layout = _Layout(h5)
        tasks = {name: ds[...] for name, ds in layout.tasks.items()}
        rows = np.concatenate([np.arange(k * layout.per_task, k * layout.per_task + n)
                               for k, n in enumerate(tasks["events_written"])] or [np.zeros(0, int)])
        events = {name: ds[...][rows] for name, ds in layout.events.items()}
        attrs = {k: h5.attrs[k] for k in h5.attrs}
    return events, tasks, attrs
