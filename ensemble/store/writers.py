"""The two writers of a run's catalog, with one API: every rank writes its own tasks (ParallelWriter,
mpio), or rank 0 writes what the others send it (Rank0Writer); both produce the same catalog.

The store is the only package that touches HDF5 under MPI, and its collective steps (create, open,
close) are here: the layout every rank makes alike is create.py's, and after creation nothing collective
is left (layout.py), so each rank writes its rows independently.
"""
import h5py

from ..config import ConfigError
from . import files
from .errors import CatalogError, writing
from .layout import Layout


def has_parallel_hdf5():
    """True if h5py is built with MPI (the parallel stack): the one place that asks."""
    return bool(h5py.get_config().mpi)


class _Writer:
    """Common API of the writers: record, commit, finish, fail, start, poll, close."""

    @classmethod
    def label(cls, n_ranks):
        """What the run log (and the catalog's `software`) call this writer on n_ranks."""
        return cls.name

    def record(self, task, restart=False):
        """TaskRecord of a task in this catalog (verified; restart: taken up from its start)."""
        return self.layout.record(task, restart)


class ParallelWriter(_Writer):
    """All ranks open one file with the mpio driver; each writes its own tasks independently."""

    name = "parallel HDF5 (mpio), independent writes"

    def __init__(self, path, comm, cfg=None, tasks=None, integrator_text="", software=""):
        self.comm = comm

        def open_file(p, mode):
            return h5py.File(p, mode, driver="mpio", comm=comm)
        if cfg is not None:
            self._create(path, open_file, cfg, tasks, integrator_text, software)
        error = None
        try:
            if cfg is None:
                self.h5 = files.open_for_writing(path, open_file)
            self.layout = Layout(self.h5)
        except CatalogError as err:
            error = str(err)
        errors = [e for e in comm.allgather(error) if e]
        if errors:
            raise CatalogError(errors[0], collective=True)

    def _create(self, path, open_file, cfg, tasks, integrator_text, software):
        """Collective create. Every step either succeeds on every rank or ends them all alike: an open that
        fails everywhere is one error; a failure inside HDF5's collective calls (which may have left the
        other ranks waiting in one) is `broken` and aborts all ranks; the blocks are reserved by rank 0
        after every rank has flushed, and its outcome broadcast, so a full disk closes the file on
        every rank together and removes it."""
        comm = self.comm
        error = None
        try:
            self.h5 = files.create_file(path, open_file, cfg, tasks, integrator_text, software)
        except CatalogError as err:
            if err.broken:
                raise
            error = str(err)
        errors = comm.allgather(error)
        if any(errors):
            if not all(errors):     # open on some ranks only: a collective close would hang
                raise CatalogError(next(e for e in errors if e), broken=True)
            raise CatalogError(errors[0], collective=True)
        if comm.Get_rank() == 0:
            try:
                files.reserve_space(path)
            except OSError as err:
                error = f"{path}: cannot create catalog ({err})"
        error = comm.bcast(error, root=0)
        if error:
            self.h5.close()
            if comm.Get_rank() == 0:
                files.discard(path)
            raise CatalogError(error, collective=True)

    def commit(self, task, start, batch, checkpoint, histories=()):
        for slot, history in histories:
            self.layout.write_history(task, slot, history)
        if batch is not None:
            self.layout.write_events(task, start, batch)
        self.layout.write_checkpoint(task, checkpoint, start + (0 if batch is None else len(batch["t"])))

    def finish(self, task, provenance):
        self.layout.write_provenance(task, provenance)

    def fail(self, task, message):
        self.layout.write_failure(task, message)

    def start(self, task, integrator_text):
        self.layout.write_start(task, integrator_text)

    def poll(self):
        pass

    def close(self):
        """Collective."""
        self.layout = None
        with writing(self.h5.filename, "the end of the run"):
            self.h5.close()


class Rank0Writer(_Writer):
    """Rank 0 owns the file; other ranks send their rows to it (no parallel HDF5 needed).

    Rank 0 writes incoming rows whenever it polls (between kernel calls) and,
    at the end, until every rank has said it is done. With one rank this is a
    plain serial writer. Every message is served where it arrives, in `poll` or in
    `close`, and each rank's "done" is counted wherever it was received.
    """

    name = "serial HDF5 on rank 0, rows sent by message"
    TAG = 17

    @classmethod
    def label(cls, n_ranks):
        return cls.name if n_ranks > 1 else "serial HDF5"

    def __init__(self, path, comm, cfg=None, tasks=None, integrator_text="", software=""):
        self.comm = comm
        self.rank = comm.Get_rank()
        self.layout = None
        self.finished_ranks = 0
        error = broken = None
        if self.rank == 0:
            try:
                if cfg is not None:
                    self.h5 = files.create_file(path, h5py.File, cfg, tasks, integrator_text, software)
                    try:
                        files.reserve_space(path)
                    except OSError as err:
                        self.h5.close()     # (no HDF5 call failed: closing is safe)
                        files.discard(path)
                        raise CatalogError(f"{path}: cannot create catalog ({err})") from None
                else:
                    self.h5 = files.open_for_writing(path, h5py.File)
                self.layout = Layout(self.h5, barrier=self._flush)
            except CatalogError as err:
                error, broken = str(err), err.broken
        error = comm.bcast(error, root=0)
        if error:
            # only rank 0 touched the file: a broken one ends rank 0 at once, the others return alike
            raise CatalogError(error, broken=bool(broken), collective=True)

    def _call(self, kind, *args):
        """Do `kind` here (rank 0) or ask rank 0 to."""
        if self.rank == 0:
            return self._do(kind, *args)
        self.comm.send((kind, *args), dest=0, tag=self.TAG)
        if kind == "record":
            answer = self.comm.recv(source=0, tag=self.TAG + 1)
            if isinstance(answer, Exception):
                raise answer
            return answer
        return None

    def record(self, task, restart=False):
        return self._call("record", task, restart)

    def commit(self, task, start, batch, checkpoint, histories=()):
        self._call("commit", task, start, batch, checkpoint, histories)

    def finish(self, task, provenance):
        self._call("finish", task, provenance)

    def fail(self, task, message):
        self._call("fail", task, message)

    def start(self, task, integrator_text):
        self._call("start", task, integrator_text)

    def _flush(self):
        with writing(self.h5.filename, "buffered data"):
            self.h5.flush()

    def _do(self, kind, *args):
        layout = self.layout
        if kind == "record":
            return layout.record(*args)
        if kind == "commit":
            task, start, batch, checkpoint, histories = args
            for slot, history in histories:
                layout.write_history(task, slot, history)
            if batch is not None:
                layout.write_events(task, start, batch)
                self._flush()   # events reach the file before the commit row points past them
            layout.write_checkpoint(task, checkpoint, start + (0 if batch is None else len(batch["t"])))
        elif kind == "finish":
            layout.write_provenance(*args)
        elif kind == "fail":
            layout.write_failure(*args)
        elif kind == "start":
            layout.write_start(*args)
        if kind in ("finish", "fail", "start"):
            self._flush()
        return None

    def _serve(self, status):
        """Carry out one request of another rank."""
        source = status.Get_source()
        msg = self.comm.recv(source=source, tag=self.TAG)
        kind = msg[0]
        if kind == "done":
            self.finished_ranks += 1
        elif kind == "record":
            try:
                answer = self._do(*msg)
            except CatalogError as err:   # the asking rank raises it (and aborts the job)
                answer = err
            self.comm.send(answer, dest=source, tag=self.TAG + 1)
        else:
            self._do(*msg)

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
            status = MPI.Status()
            while self.finished_ranks < self.comm.Get_size() - 1:
                self.comm.Probe(source=MPI.ANY_SOURCE, tag=self.TAG, status=status)
                self._serve(status)
            self.layout = None
            with writing(self.h5.filename, "the end of the run"):
                self.h5.close()
        else:
            self.comm.send(("done",), dest=0, tag=self.TAG)
        self.comm.Barrier()


WRITERS = {"parallel": ParallelWriter, "rank0": Rank0Writer}


def writer_key(name, n_ranks, parallel_hdf5):
    """output.writer -> the key of WRITERS a run on n_ranks uses; parallel_hdf5: has_parallel_hdf5().

    The only statement of the rule: runs (choose_writer) and validate (environment.py) both use it.
    'auto' -> parallel HDF5 when h5py has MPI support and there is more than one rank.
    """
    if name == "parallel" and not parallel_hdf5:
        raise ConfigError("output.writer = 'parallel' needs h5py built with MPI support, and this h5py has "
                          "none (use 'auto' or 'rank0', or install the parallel stack)")
    if name == "auto":
        return "parallel" if n_ranks > 1 and parallel_hdf5 else "rank0"
    return name


def choose_writer(name, comm):
    """The writer class for output.writer = name on the ranks of comm."""
    return WRITERS[writer_key(name, comm.Get_size(), has_parallel_hdf5())]
