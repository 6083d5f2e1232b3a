"""What a catalog stores: its format, its datasets (unit, shape, meaning) and the codes in them.

Every task records exactly `run.events` events, so the whole catalog is laid out (and allocated)
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
"""
import numpy as np

from ..config import LAW_KEYS
from ..model import laws
from ..model.workspace import KIND_CREEP, KIND_EVENT, NEPISODE

FORMAT = "bk-catalog-8"
# older formats this version reads (not resumes), and what they lack: bk-catalog-7 ran chains only (no
# /tasks/geometry, /tasks/M, /tasks/l_across, /events/across_first, /events/across_last: the reader supplies
# chain, 1, NaN, 0, 0) and keeps its checkpoints' episode tables without the extents across strike; bk-catalog-6
# has no /events/stress_drop and no nucleation columns (the reader supplies NaN, and 0 for the counts);
# bk-catalog-5 keeps a creep state of another layout in its checkpoints (its episode table without the episodes'
# energy, EPISODE_COLUMNS);
# bk-catalog-4 has no /events/kind and /events/ending (every row an inertial event; the reader supplies kind 0,
# ending 0) and no creep state in its checkpoints; bk-catalog-3 lacks also tables_crc and /tasks/record_crc (its
# tables are checked against its config only). Only FORMAT is written and resumed.
OLDER = {
    "bk-catalog-7": "written before the geometry was a choice (a chain; another creep state in its checkpoints)",
    "bk-catalog-6": "written before events kept their stress drop and nucleation (no /events/stress_drop)",
    "bk-catalog-5": "written before creep episodes kept their energy (another creep state in its checkpoints)",
    "bk-catalog-4": "written before the creep phase (no /events/kind, no creep state in its checkpoints)",
    "bk-catalog-3": "written before its tables were checksummed",
}
READABLE = {*OLDER, FORMAT}
# formats with tables_crc and /tasks/record_crc; with /events/kind, /events/ending and /checkpoint/creep
CHECKSUMMED = {"bk-catalog-4", "bk-catalog-5", "bk-catalog-6", "bk-catalog-7", FORMAT}
WITH_CREEP = {"bk-catalog-5", "bk-catalog-6", "bk-catalog-7", FORMAT}
# columns of the episode table in a checkpoint's creep state (Workspace.creep_state), by format
EPISODE_COLUMNS = {"bk-catalog-5": 14, "bk-catalog-6": 16, "bk-catalog-7": 16, FORMAT: NEPISODE}

# /events/kind: what a row is, KIND_EVENT (0) or KIND_CREEP (1) (ensemble/model/workspace.py, imported above)
# /events/ending: 0 an inertial event; a creep episode 1 whose blocks all stopped, 2 taken over by an event
ENDING_EVENT, ENDING_STOPPED, ENDING_TAKEN_OVER = 0, 1, 2
EVENT_FIELDS = {
    "task": np.int64, "t": np.float64, "epicenter": np.int64, "mu": np.float64,
    "slip": np.float64, "first": np.int64, "last": np.int64, "n_slipped": np.int64,
    "boundary": np.bool_, "duration": np.float64, "kind": np.int8, "ending": np.int8, "stress_drop": np.float64,
    "n_onset": np.int64, "t_spread": np.float64, "t_widest": np.float64, "n_widest": np.int64,
    "across_first": np.int64, "across_last": np.int64,
}
# the columns each format stores (its events CRC covers these, in this order); the reader supplies the others
# as SUPPLIED says
STORED_EVENT_FIELDS = {
    "bk-catalog-3": tuple(EVENT_FIELDS)[:10], "bk-catalog-4": tuple(EVENT_FIELDS)[:10],
    "bk-catalog-5": tuple(EVENT_FIELDS)[:12], "bk-catalog-6": tuple(EVENT_FIELDS)[:12],
    "bk-catalog-7": tuple(EVENT_FIELDS)[:17], FORMAT: tuple(EVENT_FIELDS),
}
SUPPLIED = {"kind": KIND_EVENT, "ending": ENDING_EVENT, "stress_drop": np.nan, "n_onset": 0, "t_spread": np.nan,
            "t_widest": np.nan, "n_widest": 0, "across_first": 0, "across_last": 0}
TASK_FIELDS = {
    "point": np.int64, "seed_index": np.int64, "N": np.int64, "l": np.float64, "nu": np.float64,
    "M": np.int64, "l_across": np.float64,     # the lattice's (model.geometry); a chain: 1, NaN
    # every friction law's keys (model/laws/); NaN for a key of another law than the task's
    **{name: np.float64 for name in LAW_KEYS},
}
LAW_BYTES = 64        # /tasks/law and /tasks/geometry: fixed-length text
GEOMETRY_TASKS = ("geometry", "M", "l_across")    # the task columns of model.geometry (bk-catalog-8)
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
    "events/first": ("index", _EVENT_ROWS, "lowest block that slipped (on a lattice: position along strike, "
                                           "0..N-1; block i lies at i % N along, i // N across)"),
    "events/last": ("index", _EVENT_ROWS, "highest block that slipped (on a lattice: along strike)"),
    "events/n_slipped": ("count", _EVENT_ROWS, "number of blocks that slipped"),
    "events/boundary": ("bool", _EVENT_ROWS, "the rupture reached block 0 or N-1 (on a lattice: an edge)"),
    "events/duration": ("model time", _EVENT_ROWS, "time from onset until all blocks are at rest (of a creep "
                                                   "episode: from its start until it ended)"),
    "events/kind": ("code", _EVENT_ROWS, f"{KIND_EVENT} an inertial event, {KIND_CREEP} a creep episode "
                                         "(quasi-static slip); absent in catalogs before bk-catalog-5: 0"),
    "events/ending": ("code", _EVENT_ROWS, f"{ENDING_EVENT} an inertial event; a creep episode {ENDING_STOPPED} "
                                           f"whose blocks all stopped, {ENDING_TAKEN_OVER} taken over by an "
                                           "inertial event; absent in catalogs before bk-catalog-5: 0"),
    "events/stress_drop": ("model force", _EVENT_ROWS, "mean over the blocks that slipped of the drop of their force "
                                                       "by the slip (the driver held at its onset position); NaN for "
                                                       "a creep episode, and in catalogs before bk-catalog-7"),
    # an event's nucleation (ensemble/model/workspace.py: D_N_ONSET ...; analysis/statistics/nucleation.py)
    "events/n_onset": ("count", _EVENT_ROWS, "blocks sliding at the onset (1, or a creeping cluster handed over to "
                                             "inertia); 0 for a creep episode and in catalogs before bk-catalog-7"),
    "events/t_spread": ("model time", _EVENT_ROWS, "time from the onset until a block beyond those started to slide "
                                                   "(NaN: none did; a creep episode; before bk-catalog-7)"),
    "events/t_widest": ("model time", _EVENT_ROWS, "time from the onset until the most blocks were sliding at once "
                                                   "(NaN: a creep episode; before bk-catalog-7)"),
    "events/n_widest": ("count", _EVENT_ROWS, "the most blocks sliding at once (the nucleation's widest zone in a "
                                              "large event; 0: a creep episode, before bk-catalog-7)"),
    "events/across_first": ("index", _EVENT_ROWS, "lowest position across strike that slipped (0..M-1 on a "
                                                  "lattice; 0 on a chain, and in catalogs before bk-catalog-8)"),
    "events/across_last": ("index", _EVENT_ROWS, "highest position across strike that slipped (as across_first)"),
    "tasks/point": ("index", _TASK_ROWS, "parameter point (position in the product of the [sweep] lists)"),
    "tasks/seed_index": ("index", _TASK_ROWS, "realisation of its point; task = point * run.seeds + seed_index"),
    "tasks/N": ("count", _TASK_ROWS, "number of blocks of the chain (of a lattice: along strike)"),
    "tasks/M": ("count", _TASK_ROWS, "blocks across strike (model.M: the lattice's rows; 1 for a chain, and in "
                                     "catalogs before bk-catalog-8)"),
    "tasks/l_across": ("1", _TASK_ROWS, "spring stiffness across strike (model.l_across; NaN for a chain)"),
    "tasks/geometry": ("text", _TASK_ROWS, "how the blocks are joined (model.geometry); absent before "
                                           "bk-catalog-8: chain"),
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
    "tasks/spawn_key": ("index", _TASK_ROWS,
                        "spawn key of the task's SeedSequence, its task index (-1 until finished)"),
    "tasks/status": ("code", _TASK_ROWS, "0 open (not started, running or interrupted), 1 finished, 2 failed"),
    "tasks/error": ("text", _TASK_ROWS,
                    f"why a failed task failed, empty otherwise (UTF-8, {TEXT_BYTES} bytes at most)"),
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
    # only where output.history > 0 (ensemble/store/histories.py); H = tasks * output.history slots, task k's
    # from k * output.history, S = output.history_snapshots, N the largest chain's
    "histories/row": ("index", "(H,)", "the event's row among its task's rows (-1: slot unused; its /events row is "
                                       "task * events_per_task + row)"),
    "histories/snapshots": ("count", "(H,)", "snapshots kept, from the onset to the event's end"),
    "histories/dropped": ("count", "(H,)", "snapshots dropped for want of rows (output.history_snapshots)"),
    "histories/crc": ("CRC-32", "(H,)", "CRC of the history (row, counts, its snapshots' data)"),
    "histories/time": ("model time", "(H, S)", "local time of each snapshot since the event's onset"),
    "histories/sliding": ("count", "(H, S)", "blocks sliding at the snapshot (one started in its step still at rest)"),
    "histories/velocity": ("model length / model time", "(H, S, N)", "each block's velocity at the snapshot"),
    "histories/slip": ("model length", "(H, S, N)", "each block's slip since the onset at the snapshot"),
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

# fields of a commit row (/checkpoint/commit[task, slot])
C_SEQ, C_DONE, C_WRITTEN, C_STATE_CRC, C_EVENTS_CRC, C_ROW_CRC = range(6)
NCOMMIT = 6
READ_CHUNK = 1 << 16                  # rows per column read at a time when verifying events

OPEN, FINISHED, FAILED = 0, 1, 2      # /tasks/status
STATUS_NAMES = {OPEN: "open", FINISHED: "finished", FAILED: "failed"}


def fixed_text(value):
    """A text as stored in /tasks/error and /tasks/integrator (UTF-8, cut at TEXT_BYTES)."""
    data = value.encode()[:TEXT_BYTES]
    return np.bytes_(data)
