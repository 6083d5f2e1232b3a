"""Reading a catalog: its tasks (committed counts from their commit rows) and their events, verified
as they stream (layout.py); a damaged catalog is one CatalogError naming the file and the task."""
import numpy as np

from .. import filekind
from ..config import LAW_KEYS
from . import files, tables
from .errors import CatalogError
from .layout import Layout
from .schema import EVENT_FIELDS, OPEN, READ_CHUNK, SUPPLIED


class Reader:
    """A catalog open for reading: its tasks (committed counts from the commit rows) and events.

        with reader.Reader(path) as cat:
            for chunk in cat.task_events(k):    # dicts of columns, verified as they stream
                ...
    """

    def __init__(self, path, damaged_ok=False):
        """damaged_ok: a task whose record is damaged (tables.py) is listed in `damaged` {task: what}
        instead of refused (a resume reruns it)."""
        self.path = str(path)
        self.damaged_ok = damaged_ok
        self.h5 = files.open_for_reading(self.path)
        try:
            self._read_tasks()
        except BaseException:
            self.h5.close()
            raise

    def _read_tasks(self):
        with filekind.reading(self.path, "the event catalog", CatalogError):
            self.layout = Layout(self.h5)
            self.attrs = {k: self.h5.attrs[k] for k in self.h5.attrs}
            self.per_task = self.layout.per_task
            self.tasks = {name: ds[...] for name, ds in self.layout.tasks.items()}
            heads = [self.layout.head(k) for k in range(self.layout.n_tasks)]
            spun = [self.layout.head(k) for k in range(self.layout.n_tasks, self.layout.n_records)]
            # each task's record (tables.py); a resume reruns a damaged one, anything else refuses it
            self.damaged = {}
            for k in range(self.layout.n_tasks):
                problem = self.layout.record_problem(k, {name: self.tasks[name][k] for name in (
                    *tables.RECORD, "record_crc", "events_written") if name in self.tasks})
                if problem and not self.damaged_ok:
                    raise self.layout._fail(k, problem)
                if problem:
                    self.damaged[k] = problem
                    self.tasks["status"][k] = OPEN     # to be rerun
        # run.branch: each point's spin-up, its events done (of attrs["spinup"])
        self.spinups = {**self.layout.spinup,
                        "events_done": np.array([0 if h is None else h.done for h in spun], dtype=np.int64)}
        self.tasks["events_written"] = np.array([0 if h is None else h.written for h in heads], dtype=np.int64)
        self.tasks["events_done"] = np.array([0 if h is None else h.done for h in heads], dtype=np.int64)
        for k in self.damaged:       # (damaged_ok) to be rerun from its start
            self.tasks["events_written"][k] = self.tasks["events_done"][k] = 0
        n = self.layout.n_tasks
        # catalogs written before there was a choice of law ran the aging law (a, b, c only)
        self.tasks.setdefault("law", np.full(n, b"aging"))
        for name in LAW_KEYS:
            self.tasks.setdefault(name, np.full(n, np.nan))
        self.tasks.setdefault("branch_of", np.full(n, -1, dtype=np.int64))   # catalogs before run.branch
        # catalogs before bk-catalog-8 ran chains
        self.tasks.setdefault("geometry", np.full(n, b"chain"))
        self.tasks.setdefault("M", np.ones(n, dtype=np.int64))
        self.tasks.setdefault("l_across", np.full(n, np.nan))
        for name in ("error", "integrator", "law", "geometry"):
            self.tasks[name] = np.array([x.decode(errors="replace") for x in self.tasks[name]])

    def task_events(self, task, chunk=READ_CHUNK, kind=None):
        """The task's committed rows in chunks; raises CatalogError if they are corrupt.

        kind: only the rows of that kind (KIND_EVENT: the inertial events, what today's statistics
        read), chunks with none left out; every row is still read and verified (consume them all).
        """
        parts = self.layout.task_events(task, int(self.tasks["events_written"][task]), chunk)
        if kind is None:
            return parts
        return rows_where(parts, lambda part: part["kind"] == kind)

    def histories(self, task):
        """The task's event histories (list of dicts: row, time (s,), velocity and slip (s, N), dropped), of
        its committed rows, verified; [] where the run kept none (ensemble/store/histories.py)."""
        if self.layout.histories is None:
            return []
        written = int(self.tasks["events_written"][task])
        return self.layout.histories.read(task, written, int(self.layout.n_blocks[task]))

    def count(self, task, kind):
        """The task's committed rows of that kind (/events/kind alone, not verified: task_events verifies)."""
        written = int(self.tasks["events_written"][task])
        if "kind" not in self.layout.events:      # (before bk-catalog-5: every row an inertial event)
            return written if kind == SUPPLIED["kind"] else 0
        base = task * self.per_task
        return int(np.count_nonzero(self.layout.events["kind"][base:base + written] == kind))

    def column(self, task, name):
        """The task's committed rows of one column (not verified: task_events verifies); e.g. the onset
        times of a regional reduction's window (analysis/region.py)."""
        written = int(self.tasks["events_written"][task])
        if name not in self.layout.events:      # (a column supplied for older formats)
            return np.full(written, SUPPLIED[name], dtype=EVENT_FIELDS[name])
        base = task * self.per_task
        return self.layout.events[name][base:base + written]

    def events(self):
        """Every committed event (dict of arrays, tasks in order), verified."""
        parts = [part for k in range(self.layout.n_tasks) for part in self.task_events(k)]
        if not parts:
            return {name: np.zeros(0, dtype=dtype) for name, dtype in EVENT_FIELDS.items()}
        return {name: np.concatenate([p[name] for p in parts]) for name in EVENT_FIELDS}

    def close(self):
        self.h5.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def rows_where(parts, keep_of):
    """The rows of chunks (dicts of columns) where keep_of(chunk) is True; chunks with none left out.
    Every chunk is still consumed, and so verified as it streams."""
    for part in parts:
        keep = keep_of(part)
        if keep.all():
            yield part
        elif keep.any():
            yield {name: column[keep] for name, column in part.items()}


def read_tasks(path, damaged_ok=False):
    """Catalog -> (rows per task, tasks: dict of arrays, attrs: dict), without the events.

    tasks["events_written"] is each task's committed event count (from its commit row).
    damaged_ok: tasks whose record is damaged are not refused (Reader); a resume reruns them.
    """
    with Reader(path, damaged_ok) as cat:
        return cat.per_task, cat.tasks, cat.attrs


def read(path):
    """Catalog -> (events: dict of arrays with only the committed rows, verified, tasks, attrs)."""
    with Reader(path) as cat:
        return cat.events(), cat.tasks, cat.attrs
