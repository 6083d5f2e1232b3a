"""What a catalog's tables must hold, checked on every read and every resume (pure numpy, no HDF5).

The events, checkpoints and commit rows carry their own checksums (integrity.py). This module
protects the rest, so that no damaged table can make a reader or a resume silently wrong:

- **Fixed at creation**: every /tasks column but a task's record and the events_written mirror (the
  parameter tables point, seed_index, N, l, nu, law, the law keys, branch_of), /spinup/*,
  /checkpoint/offset, /checkpoint/creep (bk-catalog-5 on: which records keep a creep state) and the root
  attributes (the stored config among them). One CRC of all of them is stored as the root attribute
  `tables_crc` at creation and verified on every open; the parameter tables are also recomputed from
  the stored config, where this version can read it, and compared (`config_problems`), so a config and
  its tables can never disagree. Catalogs of format bk-catalog-3, written before these checksums, are
  read with the comparison and the consistency rules only. (Whether /checkpoint/creep is what this
  version's kernel needs is asked only by a resume: layout.py.)
- **A task's record** (`RECORD`): /tasks/status, error, integrator and the provenance columns, written
  when a task finishes, fails or is taken up again. Each write of them ends with /tasks/record_crc[k],
  the CRC of the task's record bound to its index. A reader refuses a record that fails it; a resume
  reruns that task from its start (a run killed between the record and its CRC leaves the same
  mismatch as a damaged byte, and rerunning is right in both cases).
- **Consistency** (`record_problems`): the status code is known, an error text belongs to a failed task
  only, a finished task has all its events committed and its provenance set (or, finished by a resume
  after its last commit, none), an unfinished one none, and the /tasks/events_written mirror equals one
  of the task's commit rows.
"""
import numpy as np

from .integrity import crc
from .schema import FAILED, FINISHED, STATUS_NAMES

# root attributes written once at creation (tables_crc itself excluded)
FIXED_ATTRS = ("config", "version", "format", "events_per_task", "transient", "spinup", "software")
# /tasks columns of a task's record, in the order of its CRC
RECORD = ("status", "error", "integrator", "rank", "wall_time", "events_per_second", "seed_entropy",
          "spawn_key")


def _bytes_of(value):
    if isinstance(value, (str, bytes, np.bytes_, np.str_)):
        return np.frombuffer(value.encode() if isinstance(value, str) else bytes(value), dtype=np.uint8)
    return np.ascontiguousarray(np.asarray(value)).view(np.uint8).ravel()


def digest(named):
    """CRC-32 of named values (dict name -> array, number or text), in name order, names included."""
    value = 0
    for name in sorted(named):
        value = crc(_bytes_of(name), value)
        value = crc(_bytes_of(named[name]), value)
    return value


def record_crc(task, values):
    """CRC of task `task`'s record: values = {column of RECORD: its value in that row}."""
    return digest({"task": np.int64(task), **{name: values[name] for name in RECORD}})


def expected_parameters(tasks, spinups, law_keys):
    """The parameter tables a run's task list implies: {column: array} (as create.create_layout writes them)."""
    out = {"point": np.array([t.point for t in tasks], dtype=np.int64),
           "seed_index": np.array([t.seed_index for t in tasks], dtype=np.int64),
           "N": np.array([t.model.N for t in tasks], dtype=np.int64),
           "l": np.array([t.model.l for t in tasks], dtype=np.float64),
           "nu": np.array([t.model.nu for t in tasks], dtype=np.float64),
           "law": np.array([t.model.law.encode() for t in tasks]),
           "geometry": np.array([t.model.geometry.encode() for t in tasks]),
           "M": np.array([t.model.M for t in tasks], dtype=np.int64),
           "l_across": np.array([np.nan if t.model.l_across is None else t.model.l_across for t in tasks]),
           "branch_of": np.array([t.point if spinups else -1 for t in tasks], dtype=np.int64)}
    for name in law_keys:
        out[name] = np.array([np.nan if getattr(t.model, name, None) is None else getattr(t.model, name)
                              for t in tasks], dtype=np.float64)
    return out


def config_problems(stored, expected):
    """Columns of the stored parameter tables that differ from what the stored config implies."""
    wrong = []
    for name, values in expected.items():
        if name not in stored:
            continue      # (a column older catalogs lack: the reader fills it in)
        have = stored[name]
        if name in ("law", "geometry"):
            have = np.array([bytes(x).rstrip(b"\0") for x in have])
        if np.shape(have) != np.shape(values):
            wrong.append(f"/tasks/{name} ({len(have)} rows, the config has {len(values)} tasks)")
            continue
        rows = np.flatnonzero(~_equal_rows(have, values))
        if len(rows):
            wrong.append(f"/tasks/{name} (task {int(rows[0])}: {have[rows[0]]!r}, the config says {values[rows[0]]!r})")
    return wrong


def _equal_rows(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        a, b = a.astype(np.float64), b.astype(np.float64)
        return (a == b) | (np.isnan(a) & np.isnan(b))
    return a == b


def record_problems(task, row, commit_written, per_task, checksummed=True):
    """What is wrong with task `task`'s record (row: {column: value}); commit_written: the events
    written by each of its valid commit rows (the one in use first), [] if none; '' if nothing.
    checksummed: the catalog has record_crc (not bk-catalog-3)."""
    status = int(row["status"])
    if status not in STATUS_NAMES:
        return f"status code {status} is not one of {sorted(STATUS_NAMES)}"
    if checksummed and row["record_crc"] != record_crc(task, row):
        return "its record (status, error, integrator, provenance) fails its checksum"
    error = bytes(row["error"]).rstrip(b"\0")
    if bool(error) != (status == FAILED):
        return f"status {STATUS_NAMES[status]} with {'an' if error else 'no'} error text"
    written = int(row["events_written"])
    if written not in {0, *commit_written}:
        return f"/tasks/events_written {written} matches none of its commit rows ({commit_written})"
    finished = status == FINISHED
    if finished and (not commit_written or commit_written[0] != per_task):
        return f"finished with {commit_written[0] if commit_written else 0} of {per_task} events committed"
    # (the stream a task drew from is run.seed and its index when a run wrote it; a catalog put together from
    # another's trajectories names theirs, which the reduction uses to refuse one trajectory counted twice)
    prov_set = (int(row["rank"]) >= 0, int(row["seed_entropy"]) >= 0, int(row["spawn_key"]) >= 0,
                np.isfinite(row["wall_time"]) and row["wall_time"] >= 0,
                np.isfinite(row["events_per_second"]) and row["events_per_second"] >= 0)
    prov_unset = (int(row["rank"]) == -1, int(row["seed_entropy"]) == -1, int(row["spawn_key"]) == -1,
                  np.isnan(row["wall_time"]), np.isnan(row["events_per_second"]))
    # (a task whose finish was recorded by a resume, its events all committed before, has none)
    if finished and not (all(prov_set) or all(prov_unset)):
        return "finished with a damaged provenance (rank, seed_entropy, spawn_key, wall_time, events/s)"
    if not finished and not all(prov_unset):
        return f"{STATUS_NAMES[status]} but with a provenance (only a finished task has one)"
    return ""
