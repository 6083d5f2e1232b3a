"""The HDF5 event catalog: schema, writer and reader.

Every task records exactly `run.events` events, so the whole catalog is laid
out when the file is created: task k owns rows [k * events, (k + 1) * events)
of every dataset in /events, and /tasks/events_written says how many of them
hold events. Writing a batch is then a plain slice assignment, with no resize.

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
    /tasks/{point, seed_index, N, l, nu, a, b, c, events_written}   one row per task
    attributes of /: config (resolved TOML text), version, format
"""
import os

import h5py
import numpy as np

from . import __version__

FORMAT = "bk-catalog-1"

EVENT_FIELDS = {
    "task": np.int64, "t": np.float64, "epicenter": np.int64, "mu": np.float64,
    "slip": np.float64, "first": np.int64, "last": np.int64, "n_slipped": np.int64,
    "boundary": np.bool_, "duration": np.float64,
}
TASK_FIELDS = {
    "point": np.int64, "seed_index": np.int64, "N": np.int64, "l": np.float64,
    "nu": np.float64, "a": np.float64, "b": np.float64, "c": np.float64,
}
_FILL = {np.int64: -1, np.float64: np.nan, np.bool_: False}
_CHUNK = 1 << 16


class CatalogError(RuntimeError):
    """A catalog that cannot be created, written or read; the message names the file."""


def partial_path(path):
    """Where a run writes until it has finished (then it is renamed to `path`)."""
    return str(path) + ".partial"


class SerialWriter:
    """Writes a catalog from one process. Same API as the parallel writer."""

    def __init__(self, path, cfg, tasks):
        self.path = str(path)
        self.events = cfg.run.events
        rows = len(tasks) * self.events
        try:
            self.h5 = h5py.File(self.path, "w")
        except OSError as err:
            raise CatalogError(f"{self.path}: cannot create catalog ({err})") from None
        self.h5.attrs["config"] = cfg.to_toml()
        self.h5.attrs["version"] = __version__
        self.h5.attrs["format"] = FORMAT
        ev = self.h5.create_group("events")
        for name, dtype in EVENT_FIELDS.items():
            ev.create_dataset(name, shape=(rows,), dtype=dtype, fillvalue=_FILL[dtype],
                              chunks=(min(max(rows, 1), _CHUNK),))
        tg = self.h5.create_group("tasks")
        for name, dtype in TASK_FIELDS.items():
            values = [getattr(t, name) if hasattr(t, name) else getattr(t.model, name) for t in tasks]
            tg.create_dataset(name, data=np.asarray(values, dtype=dtype))
        tg.create_dataset("events_written", data=np.zeros(len(tasks), dtype=np.int64))

    def write(self, task_index, start, batch):
        """Store events start .. start+len-1 of a task (batch: dict of equal-length arrays)."""
        n = len(batch["t"])
        lo = task_index * self.events + start
        if start + n > self.events:
            raise CatalogError(f"{self.path}: task {task_index} has more than {self.events} events")
        for name in EVENT_FIELDS:
            self.h5["events"][name][lo:lo + n] = batch[name]
        self.h5["tasks"]["events_written"][task_index] = start + n
        self.h5.flush()

    def close(self):
        self.h5.close()


def read(path):
    """Catalog -> (events: dict of arrays with only the written rows, tasks: dict, attrs: dict)."""
    if not os.path.exists(path):
        raise CatalogError(f"{path}: no such catalog")
    with h5py.File(path, "r") as h5:
        if h5.attrs.get("format") != FORMAT:
            raise CatalogError(f"{path}: not an event catalog of this package")
        tasks = {name: h5["tasks"][name][...] for name in h5["tasks"]}
        per_task = h5["events"]["t"].shape[0] // max(len(tasks["point"]), 1)
        rows = np.concatenate([np.arange(k * per_task, k * per_task + n)
                               for k, n in enumerate(tasks["events_written"])] or [np.zeros(0, int)])
        events = {name: h5["events"][name][...][rows] for name in EVENT_FIELDS}
        attrs = {k: h5.attrs[k] for k in h5.attrs}
    return events, tasks, attrs
