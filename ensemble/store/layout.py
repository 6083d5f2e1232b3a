"""An open catalog's structure: its datasets checked to fit together, its tables verified, and each
task's rows read (verified) and written in commit order.

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
import numpy as np

from ..config import LAW_KEYS, ConfigError, loads
from ..model.workspace import KIND_EVENT, NEPISODE
from ..sweep import spinups as spinup_points, task_list
from . import tables
from .checkpoint import Checkpoint, Head, TaskRecord, carries_creep, state_size
from .errors import CatalogError, writing
from .histories import GROUP, Histories
from .integrity import EventCrc, commit_crc, crc, event_problems
from .schema import (C_DONE, C_EVENTS_CRC, C_ROW_CRC, C_SEQ, C_STATE_CRC, C_WRITTEN, CHECKSUMMED, EPISODE_COLUMNS,
                     EVENT_FIELDS, FAILED, FINISHED, NCOMMIT, OPEN, READ_CHUNK, STORED_EVENT_FIELDS, SUPPLIED,
                     WITH_CREEP, fixed_text)


class Layout:
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
        self.event_fields = STORED_EVENT_FIELDS.get(self.format, tuple(EVENT_FIELDS))
        try:
            self.events = {name: h5["events"][name] for name in self.event_fields}
            self.tasks = {name: h5["tasks"][name] for name in h5["tasks"]}
            self.state = h5["checkpoint"]["state"]
            self.offset = h5["checkpoint"]["offset"][...]
            self.commit = h5["checkpoint"]["commit"]
            self.per_task = int(h5.attrs["events_per_task"])
            self.transient = int(h5.attrs["transient"])
            self.n_blocks = self.tasks["N"][...] * (self.tasks["M"][...] if "M" in self.tasks else 1)
            # spin-ups (run.branch): records n_tasks + point of /checkpoint, after the tasks'
            self.spinup_events = int(h5.attrs.get("spinup", 0))
            self.spinup = {name: ds[...] for name, ds in h5["spinup"].items()} if "spinup" in h5 else {}
            # which records keep a creep state in their slots (none before bk-catalog-5)
            self.creep = (h5["checkpoint"]["creep"][...].astype(np.int64) if self.format in WITH_CREEP else None)
            # event histories (histories.py), where the run keeps them
            self.histories = Histories(h5, self.path) if GROUP in h5 else None
        except (KeyError, OSError, ValueError) as err:
            raise CatalogError(f"{self.path}: damaged catalog ({err})") from None
        n_tasks = len(self.n_blocks)
        self.record_blocks = np.concatenate([self.n_blocks, self.spinup.get("N", np.zeros(0, np.int64))])
        n_records = len(self.record_blocks)
        if self.creep is None:
            self.creep = np.zeros(n_records, dtype=np.int64)
        columns = EPISODE_COLUMNS.get(self.format, NEPISODE)
        self.slot_sizes = np.array([state_size(int(n), c == 1, columns)
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

    def _fail(self, task, what):
        return CatalogError(f"{self.path}: task {task}: {what} (corrupt catalog)")

    def _verify_tables(self):
        """The tables fixed at creation against their checksum, and against the stored config."""
        stored = self.h5.attrs.get("tables_crc")
        if self.protected and (stored is None or int(stored) != fixed_digest(self.h5)):
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
        if self.histories is not None and task < self.n_tasks:
            rec.histories = self.histories.kept(task, head.written)
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

    def write_history(self, task, slot, history):
        """One event history (histories.py), before the commit whose rows include its event."""
        if self.histories is None:
            raise CatalogError(f"{self.path}: task {task}: an event history for a catalog laid out without them")
        self.histories.write(task, slot, history)

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
            self.tasks["error"][task] = fixed_text(message)
            self.tasks["status"][task] = FAILED
            self._seal(task)
        self._write(task, "failure record", write)

    def write_start(self, task, integrator_text):
        """A task taken up from its start (again): its integrator, status open, no error."""
        def write():
            self.tasks["integrator"][task] = fixed_text(integrator_text)
            self.tasks["error"][task] = fixed_text("")
            self.tasks["status"][task] = OPEN
            self._seal(task)
        self._write(task, "start record", write)

_REWRITTEN = {*tables.RECORD, "record_crc", "events_written"}


def fixed_digest(h5):
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

