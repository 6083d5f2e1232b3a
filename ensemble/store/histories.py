"""Event histories in the catalog (/histories, only where output.history > 0): for each task its first
output.history recorded events of magnitude >= output.history_mu, their velocity and slip profiles at the
snapshots the kernel took (ensemble/model/history.py).

    /histories/row        (tasks * K,) int64    the event's row among its task's rows (its /events row is
                                                task * events_per_task + row); -1: slot unused
    /histories/snapshots  (tasks * K,) int64    snapshots kept (rows of time, velocity, slip that hold data)
    /histories/dropped    (tasks * K,) int64    snapshots dropped for want of rows (the last row is the end)
    /histories/crc        (tasks * K,) int64    CRC of the history (row, counts, its snapshots' data)
    /histories/time       (tasks * K, S) float64       local time since the event's onset (model time)
    /histories/sliding    (tasks * K, S) int64         blocks sliding (one started in the step is still at rest)
    /histories/velocity   (tasks * K, S, N) float64    each block's velocity at that time (model length / time)
    /histories/slip       (tasks * K, S, N) float64    each block's slip since the onset (model length)

K = output.history (attribute `per_task`), S = output.history_snapshots (`snapshots`), N the largest chain
(a task of a shorter chain fills its first N columns; attribute `blocks`). Task k's histories are slots
k K .. k K + K - 1, in the order of their rows. Like /events, the large datasets are allocated at creation and
never filled (only what is written takes space on disk). A history is written before the commit whose rows
include its event, and read only if that commit holds (row < the task's committed rows) and its CRC holds: a
run killed between the two leaves a slot that the resumed run writes again, the same.
"""
import numpy as np

from .errors import CatalogError, writing
from .integrity import crc

GROUP = "histories"
SCALARS = ("row", "snapshots", "dropped", "crc")


def size_bound(cfg, tasks):
    """Bytes the /histories of `tasks` may take at most."""
    if cfg.output.history == 0:
        return 0
    blocks = max(t.model.blocks for t in tasks)
    return len(tasks) * cfg.output.history * (8 * len(SCALARS) + 8 * cfg.output.history_snapshots * (2 + 2 * blocks))


def history_crc(row, snapshots, dropped, time, sliding, velocity, slip):
    start = crc(np.array([row, snapshots, dropped], dtype=np.int64))
    start = crc(np.asarray(sliding, dtype=np.int64), start)
    for part in (time, velocity, slip):
        start = crc(np.asarray(part, dtype=np.float64), start)
    return start


class Histories:
    """The /histories of an open catalog: written by the rank that runs a task, read after verification."""

    def __init__(self, h5, path):
        self.path = path
        g = h5[GROUP]
        self.per_task, self.snapshots, self.blocks = (int(g.attrs[k]) for k in ("per_task", "snapshots", "blocks"))
        self.ds = {name: g[name] for name in (*SCALARS, "time", "sliding", "velocity", "slip")}

    def write(self, task, slot, history):
        """One history (a dict: row, time and sliding (s,), velocity and slip (s, n), dropped) into the task's
        slot."""
        s, n = history["velocity"].shape
        if not (0 <= slot < self.per_task and 1 <= s <= self.snapshots and n <= self.blocks):
            raise CatalogError(f"{self.path}: task {task}: a history of {s} snapshots of {n} blocks for slot {slot} "
                               f"(the catalog keeps {self.per_task} of at most {self.snapshots} x {self.blocks})")
        k = task * self.per_task + slot
        scalars = (int(history["row"]), s, int(history["dropped"]))
        with writing(self.path, f"task {task}'s event history {slot}"):
            self.ds["time"][k, :s] = history["time"]
            self.ds["sliding"][k, :s] = history["sliding"]
            self.ds["velocity"][k, :s, :n] = history["velocity"]
            self.ds["slip"][k, :s, :n] = history["slip"]
            self.ds["crc"][k] = history_crc(*scalars, history["time"], history["sliding"], history["velocity"],
                                            history["slip"])
            self.ds["dropped"][k] = scalars[2]
            self.ds["snapshots"][k] = s
            self.ds["row"][k] = scalars[0]     # last: the slot holds a history from here on

    def kept(self, task, written):
        """The task's histories of committed rows (row < written): a prefix of its slots; their count."""
        rows = self.ds["row"][task * self.per_task:(task + 1) * self.per_task]
        return int(np.count_nonzero((rows >= 0) & (rows < written)))

    def read(self, task, written, n_blocks):
        """The task's committed histories (list of dicts: row, time, sliding, velocity, slip, dropped), verified."""
        out = []
        for slot in range(self.kept(task, written)):
            k = task * self.per_task + slot
            row, s, dropped, stored = (int(self.ds[name][k]) for name in SCALARS)
            if not 1 <= s <= self.snapshots:
                raise CatalogError(f"{self.path}: task {task}: event history {slot} has {s} snapshots (corrupt "
                                   f"catalog)")
            h = {"row": row, "dropped": dropped, "time": self.ds["time"][k, :s], "sliding": self.ds["sliding"][k, :s],
                 "velocity": self.ds["velocity"][k, :s, :n_blocks], "slip": self.ds["slip"][k, :s, :n_blocks]}
            if history_crc(row, s, dropped, h["time"], h["sliding"], h["velocity"], h["slip"]) != stored:
                raise CatalogError(f"{self.path}: task {task}: event history {slot} (row {row}) fails its checksum "
                                   f"(corrupt catalog)")
            out.append(h)
        return out
