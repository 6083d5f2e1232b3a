"""The HDF5 event catalog: schema, checkpoints, writers and reader.

This is the only module that touches HDF5 under MPI. Every task records
exactly `run.events` events, so the whole catalog is laid out (and allocated)
when the file is created, collectively: task k owns rows
[k * events, (k + 1) * events) of every dataset in /events and its own slice of
/checkpoint. After creation nothing structural changes (no resize, no new
objects, no attribute writes), so each rank writes its own task's rows with
independent writes and nothing collective is left in the hot path; a process
killed at any moment leaves a file whose metadata is intact.

    /events/*       one row per inertial event or creep episode (/events/kind; run.events counts both);
                    task k owns rows [k * E, (k + 1) * E), E = events_per_task
    /tasks/*        one row per task: its parameters, committed count, provenance, status
    /checkpoint/*   per task two slots of its state and a commit row for each; with run.branch
                    then per parameter point its spin-up's (record n_tasks + point)
    /spinup/*       with run.branch only: one row per point's spin-up (whose state its tasks branch from)
    attributes of /: config (resolved TOML text), version, format, events_per_task, transient
                    (events each task discards: run.transient, or with run.branch run.decorrelation),
                    spinup (with run.branch only: events of each spin-up, run.transient),
                    software (MPI, HDF5, versions and writer of the run that created it)

Every dataset is a line of the table DATASETS below (unit, shape, meaning; printed at the end of
this docstring); each dataset carries that line as its `description` attribute, written once
at creation, so `h5dump -A` or any HDF5 viewer explains the file. Catalogs written before the
attribute existed read the same.

Commit order. A batch is committed as: its event rows (past the rows any commit
points to), then the checkpoint into the slot not in use, then that slot's commit
row with the next sequence number (a single write of one row), then the
/tasks/events_written mirror. The commit row with the highest valid sequence is the
task's truth for readers and for resume; a crash before its write leaves the
previous row, whose slot and events are untouched, so no crash moment loses or
double-counts an event (tests/test_faults.py crashes at every write of a batch).
The serial writer flushes between these steps so that they reach the file in order.

Integrity. Checkpoint slots, each task's event columns and the commit rows carry
CRC-32 checksums (integrity.py), verified with range checks on resume and on read:
a corrupt catalog fails naming the task and what is wrong, never resumes or reduces
silently wrong.
"""
import os
from dataclasses import dataclass

import h5py
import numpy as np

from . import __version__
from . import space, tables
from .config import LAW_KEYS, ConfigError, loads
from .model import laws
from .tasks import spinups as spinup_points, task_list
from .integrity import EventCrc, commit_crc, crc, event_problems
from .model.workspace import KIND_CREEP, KIND_EVENT, NEPISODE, Workspace
from .tables import FAILED, FINISHED, OPEN, STATUS_NAMES

FORMAT = "bk-catalog-6"
# older formats this version reads (not resumes), and what they lack: bk-catalog-5 keeps a creep state of
# another layout in its checkpoints (its episode table without the episodes' energy, EPISODE_COLUMNS);
# bk-catalog-4 has no /events/kind and /events/ending (every row an inertial event; the reader supplies kind 0,
# ending 0) and no creep state in its checkpoints; bk-catalog-3 lacks also tables_crc and /tasks/record_crc (its
# tables are checked against its config only). Only FORMAT is written and resumed.
OLDER = {
    "bk-catalog-5": "written before creep episodes kept their energy (another creep state in its checkpoints)",
    "bk-catalog-4": "written before the creep phase (no /events/kind, no creep state in its checkpoints)",
    "bk-catalog-3": "written before its tables were checksummed",
}
READABLE = {*OLDER, FORMAT}
CHECKSUMMED = {"bk-catalog-4", "bk-catalog-5", FORMAT}      # formats with tables_crc and /tasks/record_crc
WITH_CREEP = {"bk-catalog-5", FORMAT}       # formats with /events/kind, /events/ending and /checkpoint/creep
# columns of the episode table in a checkpoint's creep state (Workspace.creep_state), by format
EPISODE_COLUMNS = {"bk-catalog-5": 14, FORMAT: NEPISODE}

# /events/kind: what a row is, KIND_EVENT (0) or KIND_CREEP (1) (ensemble/model/workspace.py, imported above)
# /events/ending: 0 an inertial event; a creep episode 1 whose blocks all stopped, 2 taken over by an event
ENDING_EVENT, ENDING_STOPPED, ENDING_TAKEN_OVER = 0, 1, 2
EVENT_FIELDS = {
    "task": np.int64, "t": np.float64, "epicenter": np.int64, "mu": np.float64,
    "slip": np.float64, "first": np.int64, "last": np.int64, "n_slipped": np.int64,
    "boundary": np.bool_, "duration": np.float64, "kind": np.int8, "ending": np.int8,
}
# the columns of the formats before bk-catalog-5 (their events CRC covers these, in this order); the reader
# supplies the others as SUPPLIED says
OLDER_EVENT_FIELDS = tuple(EVENT_FIELDS)[:10]
SUPPLIED = {"kind": KIND_EVENT, "ending": ENDING_EVENT}
TASK_FIELDS = {
    "point": np.int64, "seed_index": np.int64, "N": np.int64, "l": np.float64, "nu": np.float64,
    # every friction law's keys (model/laws/); NaN for a key of another law than the task's
    **{name: np.float64 for name in LAW_KEYS},
}
LAW_BYTES = 64        # /tasks/law: fixed-length text
PROVENANCE_FIELDS = {
    "rank": np.int64, "wall_time": np.float64, "events_per_second": np.float64,
    "seed_entropy": np.int64, "spawn_key": np.int64,
}
TEXT_BYTES = 512                      # /tasks/error and /tasks/integrator: fixed-length text

# Every dataset, one line each: (unit, shape, meaning). The model is dimensionless
# (docs/numerics.md): "model time", "model length" (slips; the plate's displacement nu t) and
# "model force" name its scaled quantities, "1" is a pure number. Written at creation as each
# dataset's `description` attribute (description()); analysis/export.py heads its CSV columns with it.
_EVENT_ROWS = "(tasks * events_per_task,), task k's rows from k * events_per_task, committed ones valid"
_TASK_ROWS = "(tasks,)"
DATASETS = {
    "events/task": ("index", _EVENT_ROWS, "task that recorded the event (row of /tasks)"),
    "events/t": ("model time", _EVENT_ROWS, "onset time of the event (of a creep episode: its start; a task's "
                                            "events are in time order, its creep episodes in the order they ended)"),
    "events/epicenter": ("index", _EVENT_ROWS, "first block to slide (0-based; of a creep episode: to creep)"),
    "events/mu": ("log10 model length", _EVENT_ROWS, "magnitude log10(slip)"),
    "events/slip": ("model length", _EVENT_ROWS, "sum of the slips of all blocks"),
    "events/first": ("index", _EVENT_ROWS, "lowest block that slipped"),
    "events/last": ("index", _EVENT_ROWS, "highest block that slipped"),
    "events/n_slipped": ("count", _EVENT_ROWS, "number of blocks that slipped"),
    "events/boundary": ("bool", _EVENT_ROWS, "the rupture reached block 0 or N-1"),
    "events/duration": ("model time", _EVENT_ROWS, "time from onset until all blocks are at rest (of a creep "
                                                   "episode: from its start until it ended)"),
    "events/kind": ("code", _EVENT_ROWS, f"{KIND_EVENT} an inertial event, {KIND_CREEP} a creep episode "
                                         "(quasi-static slip); absent in catalogs before bk-catalog-5: 0"),
    "events/ending": ("code", _EVENT_ROWS, f"{ENDING_EVENT} an inertial event; a creep episode {ENDING_STOPPED} "
                                           f"whose blocks all stopped, {ENDING_TAKEN_OVER} taken over by an "
                                           "inertial event; absent in catalogs before bk-catalog-5: 0"),
    "tasks/point": ("index", _TASK_ROWS, "parameter point (position in the product of the [sweep] lists)"),
    "tasks/seed_index": ("index", _TASK_ROWS, "realisation of its point; task = point * run.seeds + seed_index"),
    "tasks/N": ("count", _TASK_ROWS, "number of blocks of the chain"),
    "tasks/l": ("1", _TASK_ROWS, "inter-block spring stiffness l (l^2 relative to the driver spring)"),
    "tasks/nu": ("model length / model time", _TASK_ROWS, "loading velocity of the driver plate"),
    "tasks/law": ("text", _TASK_ROWS, "friction law (model.law); absent in catalogs written before there was a "
                                      "choice: aging"),
    **{f"tasks/{name}": (key.unit, _TASK_ROWS, f"{key.meaning} (model.{name} of the {law.name} law; NaN for "
                                               f"another law; absent in older catalogs: NaN)")
       for law in laws.LAWS.values() for name, key in law.keys.items()},
    "tasks/events_written": ("count", _TASK_ROWS,
                             "events of the task stored so far (a mirror; readers use /checkpoint/commit)"),
    "tasks/rank": ("index", _TASK_ROWS, "MPI rank that finished the task (-1 until then)"),
    "tasks/wall_time": ("s", _TASK_ROWS, "wall-clock time the task took on that rank (NaN until finished)"),
    "tasks/events_per_second": ("1/s", _TASK_ROWS,
                                "recorded events per second of kernel time (NaN until finished)"),
    "tasks/seed_entropy": ("1", _TASK_ROWS, "run.seed: the task drew from SeedSequence(seed_entropy, "
                                            "spawn_key=(spawn_key,)) (-1 until finished)"),
    "tasks/spawn_key": ("index", _TASK_ROWS, "spawn key of the task's SeedSequence, its task index (-1 until finished)"),
    "tasks/status": ("code", _TASK_ROWS, "0 open (not started, running or interrupted), 1 finished, 2 failed"),
    "tasks/error": ("text", _TASK_ROWS, f"why a failed task failed, empty otherwise (UTF-8, {TEXT_BYTES} bytes at most)"),
    "tasks/integrator": ("text", _TASK_ROWS, "the task's [integrator] as TOML (a failed task may be rerun "
                                             f"with another; UTF-8, {TEXT_BYTES} bytes at most)"),
    "tasks/record_crc": ("CRC-32", _TASK_ROWS, "CRC of the task's record (status, error, integrator, provenance; "
                                              "ensemble/tables.py), rewritten with it"),
    "tasks/branch_of": ("index", _TASK_ROWS, "the spin-up (row of /spinup, = its point) whose state the task "
                                             "started from, perturbed (run.branch); -1: its own initial state"),
    "spinup/point": ("index", "(points,)", "parameter point of the spin-up (run.branch only)"),
    "spinup/spawn_key": ("index", "(points,)", "the task whose initial state the spin-up started from (its "
                                                "point's seed 0); it ran run.transient events from there"),
    "spinup/N": ("count", "(points,)", "number of blocks of the spin-up's chain"),
    "checkpoint/state": ("mixed", "(sum over tasks, then spin-ups, of 2 (4 N + 2 + creep * C(N)),)",
                         "per task two slots of [force (N, model force), psi = ln theta (N), since (2N, model "
                         "time), clock (2, model time), then where /checkpoint/creep is 1 the creep phase's "
                         "state (C(N) = Workspace.creep_size(N) values, Workspace.creep_state; in bk-catalog-5 "
                         "14 columns per episode, not 16)]: block i's force "
                         "and psi hold at the two-float time (since[2i], since[2i+1]); clock = (hi, lo) now"),
    "checkpoint/creep": ("bool", "(tasks + spin-ups,)", "1: the record's chain can creep (model/creep.py "
                                                         "possible) and its slots hold its creep state; absent in "
                                                         "catalogs before bk-catalog-5: 0"),
    "checkpoint/offset": ("index", "(tasks + spin-ups,)", "start of each task's (then spin-up's) two slots in "
                                                          "/checkpoint/state"),
    "checkpoint/commit": ("count, CRC-32", "(tasks + spin-ups, 2 slots, 6)",
                          "per task and slot: [sequence, events done incl. transient, events written, CRC of "
                          "the state slot, CRC of the written events, CRC of the row]; the valid row with the "
                          "highest sequence is the task's truth"),
}
# columns of Reader.tasks that are not /tasks datasets or are read from elsewhere
READER_TASKS = {
    "events_written": ("count", _TASK_ROWS, "events of the task committed (from its checksummed commit row)"),
    "events_done": ("count", _TASK_ROWS, "events the task has simulated, its transient included (from its "
                                         "commit row)"),
}


def description(entry):
    """(unit, shape, meaning) -> the one line stored as a dataset's `description` attribute."""
    unit, shape, meaning = entry
    return f"{meaning} [{unit}]; shape {shape}"


def schema(table=None):
    """The table of datasets as text, one line per dataset (the end of this module's docstring)."""
    table = DATASETS if table is None else table
    width = max(len(name) for name in table) + 1
    return "\n".join(f"    /{name:{width}s} {description(entry)}" for name, entry in table.items())


if __doc__:    # (None under python -OO)
    __doc__ += "\nDatasets (DATASETS):\n\n" + schema() + "\n"

_FILL = {np.int64: -1, np.float64: np.nan, np.bool_: False, np.int8: -1}
# fields of a commit row (/checkpoint/commit[task, slot])
C_SEQ, C_DONE, C_WRITTEN, C_STATE_CRC, C_EVENTS_CRC, C_ROW_CRC = range(6)
NCOMMIT = 6
READ_CHUNK = 1 << 16                  # rows per column read at a time when verifying events


class CatalogError(RuntimeError):
    """A catalog that cannot be created, written or read; the message names the file.

    broken: a write failed, and HDF5 may fail again (or crash) on anything else done with
    the open file, closing included: the caller should end the process without touching it.
    collective: raised on every rank alike (no abort of the others is needed).
    """

    def __init__(self, message, broken=False, collective=False):
        super().__init__(message)
        self.broken = broken
        self.collective = collective


def _reason(err):
    """The useful part of an HDF5 error: its errno text where it names one, else the first line."""
    text = str(err)
    if "error message = '" in text:
        return text.split("error message = '", 1)[1].split("'", 1)[0]
    return text.splitlines()[0] if text else type(err).__name__


def partial_path(path):
    """Where a run writes until every task has finished (then renamed to `path`)."""
    return str(path) + ".partial"


def has_parallel_hdf5():
    """True if h5py is built with MPI (the parallel stack): the one place that asks."""
    return bool(h5py.get_config().mpi)


def carries_creep(model):
    """A record of this model (config.Model) keeps a creep state in its checkpoint slots: some block of its
    chain can creep (model/creep.py `possible`; not for a law that never creeps, nor above the blocks'
    stiffness). Fixed at creation in /checkpoint/creep."""
    from .config import Integrator
    from .integrators import kernel_params
    from .model.creep import possible
    return bool(possible(kernel_params(model, Integrator()), model.N))


def _state_size(n, creep=False, episode_columns=NEPISODE):
    """Floats of one checkpoint slot of an n-block record (creep: with its creep state, of an episode table
    of `episode_columns`, EPISODE_COLUMNS)."""
    return 4 * n + 2 + (Workspace.creep_size(n, episode_columns) if creep else 0)


def _text(value):
    data = value.encode()[:TEXT_BYTES]
    return np.bytes_(data)


class Checkpoint:
    """A task's between-events state: forces, psi, their times (N x 2), compensated clock, events done,
    and for a chain that can creep its creep phase's state (Workspace.creep_state; None: it has none)."""

    def __init__(self, force, psi, since, clock, done, creep=None):
        self.force, self.psi, self.since, self.clock, self.done = force, psi, since, clock, done
        self.creep = creep

    def pack(self):
        return np.concatenate([self.force, self.psi, self.since.ravel(), self.clock,
                               *(() if self.creep is None else (self.creep,))])

    @classmethod
    def unpack(cls, flat, done, n):
        """The inverse of pack for an n-block chain (a creep state if flat is longer than 4 n + 2)."""
        base = _state_size(n)
        return cls(flat[:n].copy(), flat[n:2 * n].copy(), flat[2 * n:4 * n].reshape(n, 2).copy(),
                   flat[4 * n:base].copy(), int(done), flat[base:].copy() if len(flat) > base else None)


@dataclass(frozen=True)
class Head:
    """The commit in use of one task: its slot and the fields of its row."""
    slot: int
    seq: int
    done: int
    written: int
    state_crc: int
    events_crc: int


@dataclass
class TaskRecord:
    """What a writer knows of a task when a rank takes it up."""
    checkpoint: Checkpoint = None   # None: start from the initial state
    written: int = 0                # events stored (the checkpoint covers them)
    status: int = OPEN
    integrator: str = ""            # its [integrator] as TOML text
    error: str = ""
    damaged: str = ""               # what is wrong with its record (tables.py): rerun it from its start


class _Layout:
    """Structure of a catalog file, created collectively and opened once.

    `barrier` is called between the steps of a commit (the serial writer flushes
    there so that the steps reach the file in order).
    """

    def __init__(self, h5, barrier=lambda: None):
        self.h5 = h5
        self.path = h5.filename
        self.barrier = barrier
        self.format = h5.attrs.get("format")
        # the event columns this catalog stores (those of its format), in the order of its events CRC
        self.event_fields = tuple(EVENT_FIELDS) if self.format in WITH_CREEP else OLDER_EVENT_FIELDS
        try:
            self.events = {name: h5["events"][name] for name in self.event_fields}
            self.tasks = {name: h5["tasks"][name] for name in h5["tasks"]}
            self.state = h5["checkpoint"]["state"]
            self.offset = h5["checkpoint"]["offset"][...]
            self.commit = h5["checkpoint"]["commit"]
            self.per_task = int(h5.attrs["events_per_task"])
            self.transient = int(h5.attrs["transient"])
            self.n_blocks = self.tasks["N"][...]
            # spin-ups (run.branch): records n_tasks + point of /checkpoint, after the tasks'
            self.spinup_events = int(h5.attrs.get("spinup", 0))
            self.spinup = {name: ds[...] for name, ds in h5["spinup"].items()} if "spinup" in h5 else {}
            # which records keep a creep state in their slots (none before bk-catalog-5)
            self.creep = (h5["checkpoint"]["creep"][...].astype(np.int64) if self.format in WITH_CREEP else None)
        except (KeyError, OSError, ValueError) as err:
            raise CatalogError(f"{self.path}: damaged catalog ({err})") from None
        n_tasks = len(self.n_blocks)
        self.record_blocks = np.concatenate([self.n_blocks, self.spinup.get("N", np.zeros(0, np.int64))])
        n_records = len(self.record_blocks)
        if self.creep is None:
            self.creep = np.zeros(n_records, dtype=np.int64)
        columns = EPISODE_COLUMNS.get(self.format, NEPISODE)
        self.slot_sizes = np.array([_state_size(int(n), c == 1, columns)
                                    for n, c in zip(self.record_blocks, self.creep)], dtype=np.int64)
        sizes = 2 * self.slot_sizes
        if (self.commit.shape != (n_records, 2, NCOMMIT) or len(self.offset) != n_records
                or self.creep.shape != (n_records,) or np.any((self.creep != 0) & (self.creep != 1))
                or any(ds.shape[0] != n_tasks * self.per_task for ds in self.events.values())
                or np.any(self.record_blocks < 1) or self.per_task < 1 or self.transient < 0
                or self.spinup_events < 0 or (self.spinup_events > 0) != bool(self.spinup)
                or np.any(self.offset != np.concatenate([[0], np.cumsum(sizes)[:-1]]))
                or self.state.shape[0] != int(sizes.sum())):
            raise CatalogError(f"{self.path}: damaged catalog (its datasets do not fit together)")
        self.n_tasks = n_tasks
        self.n_records = n_records
        self.protected = self.format in CHECKSUMMED      # (bk-catalog-3: no tables_crc, no record_crc)
        self._records = None    # the records' Tasks (tasks, then spin-ups) of the stored config, if it parses
        self._verify_tables()
        self._crc = {}    # task -> EventCrc of its rows written so far (on the writing process)
        self._head = {}   # task -> Head in use (on the writing process)

    @staticmethod
    def create(h5, cfg, tasks, integrator_text, software=""):
        """Every dataset and attribute of the catalog (call on every rank with the same values).

        software: environment.software() of the creating run, stored as it is (never updated on resume:
        the metadata does not change after creation, which lets readers read while a run writes).
        """
        rows = len(tasks) * cfg.run.events
        spinups = spinup_points(cfg, tasks)
        h5.attrs["config"] = cfg.to_toml()
        h5.attrs["version"] = __version__
        h5.attrs["format"] = FORMAT
        h5.attrs["events_per_task"] = cfg.run.events
        h5.attrs["transient"] = cfg.run.discarded
        if spinups:
            h5.attrs["spinup"] = cfg.run.transient
        h5.attrs["software"] = software
        ev = h5.create_group("events")
        for name, dtype in EVENT_FIELDS.items():
            # never fill: a full run would otherwise write the whole catalog twice; rows past
            # a task's committed count are undefined and never read
            ev.create_dataset(name, shape=(rows,), dtype=dtype, fillvalue=_FILL[dtype], fill_time="never",
                              dcpl=_early_allocation())
        tg = h5.create_group("tasks")
        for name, dtype in TASK_FIELDS.items():
            values = [getattr(t, name) if name in ("point", "seed_index") else getattr(t.model, name)
                      for t in tasks]
            tg.create_dataset(name, data=np.asarray([np.nan if v is None else v for v in values], dtype=dtype))
        tg.create_dataset("law", data=np.array([_text(t.model.law) for t in tasks], dtype=f"S{LAW_BYTES}"))
        tg["law"].attrs["conventions"] = "\n".join(f"{law.name}: {law.convention}" for law in laws.LAWS.values()
                                                   if any(t.model.law == law.name for t in tasks))
        tg.create_dataset("events_written", data=np.zeros(len(tasks), dtype=np.int64))
        for name, dtype in PROVENANCE_FIELDS.items():
            tg.create_dataset(name, shape=(len(tasks),), dtype=dtype, fillvalue=_FILL[dtype])
        tg.create_dataset("status", data=np.full(len(tasks), OPEN, dtype=np.int64))
        tg.create_dataset("error", shape=(len(tasks),), dtype=f"S{TEXT_BYTES}")
        tg.create_dataset("integrator", data=np.full(len(tasks), _text(integrator_text), dtype=f"S{TEXT_BYTES}"))
        tg.create_dataset("branch_of", data=np.array([t.point if spinups else -1 for t in tasks], dtype=np.int64))
        if spinups:
            sg = h5.create_group("spinup")
            sg.create_dataset("point", data=np.array([t.point for t in spinups], dtype=np.int64))
            sg.create_dataset("spawn_key", data=np.array([t.index for t in spinups], dtype=np.int64))
            sg.create_dataset("N", data=np.array([t.model.N for t in spinups], dtype=np.int64))
        records = list(tasks) + spinups
        creep = np.array([carries_creep(t.model) for t in records], dtype=np.int8)
        sizes = np.array([2 * _state_size(t.model.N, c) for t, c in zip(records, creep)], dtype=np.int64)
        offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        cp = h5.create_group("checkpoint")
        cp.create_dataset("state", shape=(int(sizes.sum()),), dtype=np.float64, fillvalue=np.nan,
                          dcpl=_early_allocation())
        cp.create_dataset("offset", data=offset)
        cp.create_dataset("creep", data=creep)
        cp.create_dataset("commit", data=np.zeros((len(sizes), 2, NCOMMIT), dtype=np.int64))
        # metadata, written once here like the rest of the layout; under mpio every rank runs
        # this with the same values in the same order, as attribute writes are collective
        columns = {name: tg[name][...] for name in tables.RECORD}
        tg.create_dataset("record_crc", data=np.array(
            [tables.record_crc(k, {name: col[k] for name, col in columns.items()}) for k in range(len(tasks))],
            dtype=np.int64))
        for name, entry in DATASETS.items():
            if name in h5:    # /spinup only with run.branch
                h5[name].attrs["description"] = description(entry)
        h5.attrs["tables_crc"] = _fixed_digest(h5)

    def _fail(self, task, what):
        return CatalogError(f"{self.path}: task {task}: {what} (corrupt catalog)")

    def _verify_tables(self):
        """The tables fixed at creation against their checksum, and against the stored config."""
        stored = self.h5.attrs.get("tables_crc")
        if self.protected and (stored is None or int(stored) != _fixed_digest(self.h5)):
            raise CatalogError(f"{self.path}: damaged catalog: its parameter tables or stored config fail "
                               f"their checksum (tables_crc); its events cannot be attributed, rerun")
        try:
            cfg = loads(self.h5.attrs["config"])
        except ConfigError:
            # intact (its checksum holds) but not this version's: e.g. a friction law added in a copy of
            # the package; its tables are protected by tables_crc alone
            return
        tasks = task_list(cfg)
        spinups = spinup_points(cfg, tasks)
        self._records = list(tasks) + spinups
        wrong = tables.config_problems({name: ds[...] for name, ds in self.tasks.items()},
                                       tables.expected_parameters(tasks, spinups, LAW_KEYS))
        if (self.per_task, self.transient, self.spinup_events) != (
                cfg.run.events, cfg.run.discarded, cfg.run.transient if spinups else 0):
            wrong.append("the root attributes events_per_task, transient, spinup")
        if wrong:
            raise CatalogError(f"{self.path}: damaged catalog: {', '.join(wrong)} disagree with its stored config")

    def record_row(self, task):
        """Task `task`'s record columns (tables.RECORD), its record_crc and events_written mirror."""
        return {name: self.tasks[name][task] for name in (*tables.RECORD, "record_crc", "events_written")
                if name in self.tasks}

    def record_problem(self, task, row=None):
        """What is wrong with a task's record (tables.record_problems), '' if nothing."""
        head = self.head(task)
        written = [] if head is None else [head.written] + [
            int(self.commit[task, slot, C_WRITTEN]) for slot in (1 - head.slot,) if any(self.commit[task, slot])]
        return tables.record_problems(task, self.record_row(task) if row is None else row, written,
                                      self.per_task, checksummed=self.protected)

    def _seal(self, task):
        """The record's CRC, after every write of a record column (the last write of each)."""
        self.tasks["record_crc"][task] = tables.record_crc(task, self.record_row(task))

    # -- reading and verifying -------------------------------------------------------------

    def head(self, task):
        """The valid commit row with the highest sequence number, or None if the task has none."""
        rows = self.commit[task]
        best = None
        for slot in (0, 1):
            row = [int(x) for x in rows[slot]]
            if not any(row):
                continue        # never written
            if row[C_ROW_CRC] != commit_crc(task, slot, row[:C_ROW_CRC]):
                raise self._fail(task, f"commit row {slot} fails its checksum")
            seq, done, written = row[C_SEQ], row[C_DONE], row[C_WRITTEN]
            # a spin-up records nothing: it is done after spinup_events
            limit, discarded = (self.per_task, self.transient) if task < self.n_tasks else (0, self.spinup_events)
            if not (seq >= 1 and 0 <= written <= limit and written == max(0, done - discarded)):
                raise self._fail(task, f"commit row {slot} out of range (sequence {seq}, done {done}, "
                                       f"written {written})")
            if best is not None and best.seq == seq:
                raise self._fail(task, "two commit rows with the same sequence number")
            if best is None or seq > best.seq:
                best = Head(slot, seq, done, written, row[C_STATE_CRC], row[C_EVENTS_CRC])
        return best

    def task_events(self, task, written, chunk=READ_CHUNK):
        """The task's first `written` events in chunks (dicts of columns), verified as they stream.

        The CRC comparison happens after the last chunk: consume the whole generator.
        """
        running = EventCrc(self.event_fields)
        base = task * self.per_task
        last_t = -np.inf
        for lo in range(0, written, chunk):
            hi = min(lo + chunk, written)
            part = {name: ds[base + lo:base + hi] for name, ds in self.events.items()}
            running.update(part)     # (the columns stored: an older catalog's CRC covers only those)
            for name, value in SUPPLIED.items():
                if name not in part:
                    part[name] = np.full(hi - lo, value, dtype=EVENT_FIELDS[name])
            part = {name: part[name] for name in EVENT_FIELDS}
            problems = event_problems(part, int(self.n_blocks[task]), lo, last_t)
            if np.any(part["task"] != task):
                problems.append(f"event {lo + int(np.argmax(part['task'] != task))}: a row of another task")
            if problems:
                raise self._fail(task, "; ".join(problems))
            inertial = part["t"][part["kind"] == KIND_EVENT]
            last_t = inertial[-1] if len(inertial) else last_t
            yield part
        self._check_events(task, written, running)
        return running

    def _check_events(self, task, written, running):
        head = self.head(task)
        expected = head.events_crc if head is not None else EventCrc(self.event_fields).combined()
        if head is not None and head.written != written:
            raise CatalogError(f"{self.path}: task {task}: asked for {written} events, {head.written} committed")
        if running.combined() != expected:
            raise self._fail(task, f"its {written} events fail their checksum")

    def verify_events(self, task, written):
        """EventCrc of the task's first `written` rows, checked against the commit in use."""
        gen = self.task_events(task, written)
        while True:
            try:
                next(gen)
            except StopIteration as stop:
                return stop.value

    def read_state(self, task, head):
        size = int(self.slot_sizes[task])
        lo = self.offset[task] + head.slot * size
        flat = self.state[lo:lo + size]
        if crc(flat) != head.state_crc:
            raise self._fail(task, f"checkpoint slot {head.slot} fails its checksum")
        if not np.all(np.isfinite(flat)):
            raise self._fail(task, f"checkpoint slot {head.slot} holds non-finite values")
        return Checkpoint.unpack(flat, head.done, int(self.record_blocks[task]))

    def record(self, task, restart=False):
        """The task's TaskRecord, its checkpoint and events verified; the writer's state for it set up.

        restart: the task is taken up from its start (a failed task rerun): nothing is read back.
        """
        head = self.head(task)
        self._check_creep_layout(task)
        self._head[task] = head
        if task >= self.n_tasks:     # a spin-up: only its state
            rec = TaskRecord()
        else:
            rec = TaskRecord(status=int(self.tasks["status"][task]),
                             integrator=self.tasks["integrator"][task].decode(errors="replace"),
                             error=self.tasks["error"][task].decode(errors="replace"))
            if not restart:
                rec.damaged = self.record_problem(task)
        if head is None or restart or rec.damaged:
            self._crc[task] = EventCrc(self.event_fields)
            return rec
        self._crc[task] = self.verify_events(task, head.written)
        rec.checkpoint = self.read_state(task, head)
        rec.written = head.written
        return rec

    def _check_creep_layout(self, task):
        """A record is continued only if its slots hold a creep state exactly when this version's kernel
        keeps one for its chain (carries_creep): a checkpoint could not hold the state, or restore it."""
        if self._records is None:     # (a config this version cannot parse: its tables_crc stands alone)
            return
        wants = carries_creep(self._records[task].model)
        if wants != bool(self.creep[task]):
            what = f"task {task}" if task < self.n_tasks else f"the spin-up of point {task - self.n_tasks}"
            raise CatalogError(f"{self.path}: {what}: its checkpoint slots were laid out "
                               f"{'with' if self.creep[task] else 'without'} a creep state, and this version "
                               f"{'keeps one' if wants else 'keeps none'} for its chain: finish it with the "
                               f"version that wrote it, or rerun")

    # -- writing ---------------------------------------------------------------------------

    def _write(self, task, what, fn):
        with writing(self.path, f"task {task}'s {what}"):
            fn()

    def write_events(self, task, start, batch):
        running = self._crc[task]
        n = len(batch["t"])
        if start != running.rows or start + n > self.per_task:
            raise CatalogError(f"{self.path}: task {task}: rows {start}-{start + n - 1} do not follow "
                               f"the {running.rows} written (of at most {self.per_task})")
        lo = task * self.per_task + start

        def write():
            for name in EVENT_FIELDS:
                self.events[name][lo:lo + n] = batch[name]
        self._write(task, "events", write)
        running.update(batch)

    def write_checkpoint(self, task, checkpoint, written):
        running = self._crc[task]
        if written != running.rows:
            raise CatalogError(f"{self.path}: task {task}: checkpoint for {written} events, "
                               f"{running.rows} written")
        head = self._head.get(task)
        slot = 0 if head is None else 1 - head.slot
        seq = 1 if head is None else head.seq + 1
        flat = checkpoint.pack()
        if len(flat) != self.slot_sizes[task]:
            raise CatalogError(f"{self.path}: task {task}: a checkpoint of {len(flat)} values for slots of "
                               f"{self.slot_sizes[task]} ({'with' if self.creep[task] else 'without'} a creep state)")
        lo = self.offset[task] + slot * len(flat)
        self._write(task, "checkpoint", lambda: self.state.__setitem__(slice(lo, lo + len(flat)), flat))
        self.barrier()
        fields = [seq, checkpoint.done, written, crc(flat), running.combined()]
        row = np.array(fields + [commit_crc(task, slot, fields)], dtype=np.int64)
        self._write(task, "commit row", lambda: self.commit.__setitem__((task, slot), row))
        self._head[task] = Head(slot, seq, checkpoint.done, written, fields[3], fields[4])
        if task < self.n_tasks:    # (a spin-up records no events)
            self._write(task, "event count", lambda: self.tasks["events_written"].__setitem__(task, written))
        self.barrier()

    def write_provenance(self, task, values):
        def write():
            for name, value in values.items():
                self.tasks[name][task] = value
            self.tasks["status"][task] = FINISHED
            self._seal(task)
        self._write(task, "provenance", write)

    def write_failure(self, task, message):
        def write():
            self.tasks["error"][task] = _text(message)
            self.tasks["status"][task] = FAILED
            self._seal(task)
        self._write(task, "failure record", write)

    def write_start(self, task, integrator_text):
        """A task taken up from its start (again): its integrator, status open, no error."""
        def write():
            self.tasks["integrator"][task] = _text(integrator_text)
            self.tasks["error"][task] = _text("")
            self.tasks["status"][task] = OPEN
            self._seal(task)
        self._write(task, "start record", write)


class writing:
    """Context of a write: any HDF5 failure becomes one CatalogError (broken) naming the file and what."""

    def __init__(self, path, what):
        self.path, self.what = path, what

    def __enter__(self):
        return self

    def __exit__(self, kind, err, tb):
        if err is None or isinstance(err, CatalogError) or not isinstance(err, Exception):
            return False
        raise CatalogError(f"{self.path}: writing {self.what} failed ({_reason(err)}); what was committed "
                           f"before stays readable; continue with `python -m ensemble resume`",
                           broken=True) from None


_REWRITTEN = {*tables.RECORD, "record_crc", "events_written"}


def _fixed_digest(h5):
    """CRC of everything fixed at a catalog's creation (tables.py): the parameter tables, /spinup,
    /checkpoint/offset and the root attributes."""
    # every /tasks column but a task's record and the events_written mirror, which runs rewrite (also the
    # columns of a law this version does not know)
    named = {f"tasks/{name}": ds[...] for name, ds in h5["tasks"].items() if name not in _REWRITTEN}
    named.update({f"spinup/{name}": ds[...] for name, ds in h5["spinup"].items()} if "spinup" in h5 else {})
    named["checkpoint/offset"] = h5["checkpoint"]["offset"][...]
    if "creep" in h5["checkpoint"]:    # (bk-catalog-5 on)
        named["checkpoint/creep"] = h5["checkpoint"]["creep"][...]
    named.update({f"@{name}": h5.attrs[name] for name in tables.FIXED_ATTRS if name in h5.attrs})
    return tables.digest(named)


def _early_allocation():
    """Dataset creation properties: file space allocated at creation, so the file's layout
    (and its metadata) never changes afterwards (serial HDF5 would allocate at the first write)."""
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)
    return dcpl


def _reserve_space(path):
    """Reserve the file's disk blocks now (space.py), so that a full disk stops a run at its start,
    not hours later; where the file system cannot reserve, a write that fails later ends the run
    with a clear error instead."""
    fd = os.open(path, os.O_RDWR)
    try:
        space.reserve(fd, os.fstat(fd).st_size, "the catalog")
    finally:
        os.close(fd)


def estimate_bytes(cfg, tasks):
    """An upper bound of the size of the catalog of `tasks` (what space.check_fits asks for)."""
    records = list(tasks) + spinup_points(cfg, tasks)
    data = (len(tasks) * cfg.run.events * sum(np.dtype(t).itemsize for t in EVENT_FIELDS.values())
            + 8 * sum(2 * _state_size(t.model.N, carries_creep(t.model)) for t in records)   # checkpoint slots
            + len(records) * (8 * (2 * NCOMMIT + 1) + 1)                      # commit rows, offsets, creep
            + len(tasks) * (8 * (len(TASK_FIELDS) + len(PROVENANCE_FIELDS) + 5) + 2 * TEXT_BYTES + LAW_BYTES))
    metadata = 4096 * (len(DATASETS) + 4) + 2 * len(cfg.to_toml()) + 64 * 1024
    return int(data * 1.01) + metadata


def _discard(path):
    try:
        os.remove(path)
    except OSError:
        pass


# files whose HDF5 write failed: kept referenced until the process ends (os._exit, or MPI_Abort), as
# freeing one makes h5py close it, which fails again (a traceback per object) or crashes
_BROKEN = []


def _create_file(path, open_file, cfg, tasks, integrator_text, software):
    """Create a catalog's layout and flush it; on failure remove the file (we hold the run's lock) and raise
    CatalogError.

    A failed HDF5 write leaves the open file in a state where anything more, closing included, may
    crash HDF5 or (under mpio) wait for ranks that are elsewhere: then the file is removed, not closed,
    and the error is `broken` (the process ends at once; under MPI all ranks abort). space.check_fits
    has made that rare: it runs before, with plain files.
    """
    try:
        h5 = open_file(path, "w")
    except (OSError, ValueError, RuntimeError) as err:
        raise CatalogError(f"{path}: cannot create catalog ({_reason(err)})") from None
    try:
        _Layout.create(h5, cfg, tasks, integrator_text, software)
        h5.flush()
        return h5
    except (OSError, ValueError, RuntimeError) as err:
        _BROKEN.append(h5)
        _discard(path)
        raise CatalogError(f"{path}: cannot create catalog ({_reason(err)})", broken=True) from None


def _open_file(path, open_file):
    try:
        h5 = open_file(path, "r+")
    except OSError as err:
        raise CatalogError(f"{path}: cannot open catalog ({err})") from None
    _check_format(h5, path, writing=True)
    return h5


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
                self.h5 = _open_file(path, open_file)
            self.layout = _Layout(self.h5)
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
            self.h5 = _create_file(path, open_file, cfg, tasks, integrator_text, software)
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
                _reserve_space(path)
            except OSError as err:
                error = f"{path}: cannot create catalog ({err})"
        error = comm.bcast(error, root=0)
        if error:
            self.h5.close()
            if comm.Get_rank() == 0:
                _discard(path)
            raise CatalogError(error, collective=True)

    def commit(self, task, start, batch, checkpoint):
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
                    self.h5 = _create_file(path, h5py.File, cfg, tasks, integrator_text, software)
                    try:
                        _reserve_space(path)
                    except OSError as err:
                        self.h5.close()     # (no HDF5 call failed: closing is safe)
                        _discard(path)
                        raise CatalogError(f"{path}: cannot create catalog ({err})") from None
                else:
                    self.h5 = _open_file(path, h5py.File)
                self.layout = _Layout(self.h5, barrier=self._flush)
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

    def commit(self, task, start, batch, checkpoint):
        self._call("commit", task, start, batch, checkpoint)

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
            task, start, batch, checkpoint = args
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


# -- reading --------------------------------------------------------------------------------

def _check_format(h5, path, writing=False):
    found = h5.attrs.get("format")
    if found == FORMAT or (found in READABLE and not writing):
        return
    h5.close()
    if found in OLDER:
        raise CatalogError(f"{path}: catalog format {found}, {OLDER[found]}: this version reads it but does not "
                           f"continue it (finish it with the older version, or rerun)")
    if isinstance(found, str) and found.startswith("bk-catalog-"):
        raise CatalogError(f"{path}: catalog format {found}, this version reads {', '.join(sorted(READABLE))} "
                           "(the checkpoint layout changed; rerun, or read it with the older version)")
    raise CatalogError(f"{path}: not an event catalog of this package")


def _open_for_reading(path):
    """Open read-only without HDF5's file lock: a catalog may be read while a run writes it.

    That is safe because a catalog's metadata is complete and flushed at creation and
    never changes afterwards; what a run is writing lies beyond the commit rows read here.
    """
    from . import filekind     # (it reads summaries' marks; imported here to keep this module's imports light)
    filekind.require(path, "catalog", CatalogError)
    try:
        h5 = h5py.File(path, "r", locking=False)
    except OSError as err:
        raise CatalogError(f"{path}: cannot read catalog ({err})") from None
    _check_format(h5, path)
    return h5


class Reader:
    """A catalog open for reading: its tasks (committed counts from the commit rows) and events.

        with catalog.Reader(path) as cat:
            for chunk in cat.task_events(k):    # dicts of columns, verified as they stream
                ...
    """

    def __init__(self, path, damaged_ok=False):
        """damaged_ok: a task whose record is damaged (tables.py) is listed in `damaged` {task: what}
        instead of refused (a resume reruns it)."""
        self.path = str(path)
        self.damaged_ok = damaged_ok
        self.h5 = _open_for_reading(self.path)
        try:
            self._read_tasks()
        except BaseException:
            self.h5.close()
            raise

    def _read_tasks(self):
        from . import filekind
        with filekind.reading(self.path, "the event catalog", CatalogError):
            self.layout = _Layout(self.h5)
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
        for name in ("error", "integrator", "law"):
            self.tasks[name] = np.array([x.decode(errors="replace") for x in self.tasks[name]])

    def task_events(self, task, chunk=READ_CHUNK, kind=None):
        """The task's committed rows in chunks; raises CatalogError if they are corrupt.

        kind: only the rows of that kind (KIND_EVENT: the inertial events, what today's statistics
        read), chunks with none left out; every row is still read and verified (consume them all).
        """
        parts = self.layout.task_events(task, int(self.tasks["events_written"][task]), chunk)
        if kind is None:
            return parts
        return _of_kind(parts, kind)

    def count(self, task, kind):
        """The task's committed rows of that kind (/events/kind alone, not verified: task_events verifies)."""
        written = int(self.tasks["events_written"][task])
        if "kind" not in self.layout.events:      # (before bk-catalog-5: every row an inertial event)
            return written if kind == SUPPLIED["kind"] else 0
        base = task * self.per_task
        return int(np.count_nonzero(self.layout.events["kind"][base:base + written] == kind))

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


def _of_kind(parts, kind):
    for part in parts:
        keep = part["kind"] == kind
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
