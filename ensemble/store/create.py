"""A catalog's layout, made once at its creation: every dataset and attribute, allocated in full.

Every task records exactly `run.events` events, so nothing structural changes after this (the layout
is in schema.py); under MPI every rank runs `create_layout` with the same values in the same order, as
HDF5's creation calls and attribute writes are collective (files.create_file opens and flushes the file).
"""
import h5py
import numpy as np

from ..version import __version__
from ..model import laws
from ..sweep import spinups as spinup_points
from . import histories, tables
from .checkpoint import carries_creep, state_size
from .layout import fixed_digest
from .schema import (DATASETS, EVENT_FIELDS, FORMAT, LAW_BYTES, NCOMMIT, OPEN, PROVENANCE_FIELDS, TASK_FIELDS,
                     TEXT_BYTES, description, fixed_text)

_FILL = {np.int64: -1, np.float64: np.nan, np.bool_: False, np.int8: -1}


def create_layout(h5, cfg, tasks, integrator_text, software=""):
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
                          dcpl=early_allocation())
    tg = h5.create_group("tasks")
    for name, dtype in TASK_FIELDS.items():
        values = [getattr(t, name) if name in ("point", "seed_index") else getattr(t.model, name)
                  for t in tasks]
        tg.create_dataset(name, data=np.asarray([np.nan if v is None else v for v in values], dtype=dtype))
    tg.create_dataset("law", data=np.array([fixed_text(t.model.law) for t in tasks], dtype=f"S{LAW_BYTES}"))
    tg.create_dataset("geometry", data=np.array([fixed_text(t.model.geometry) for t in tasks], dtype=f"S{LAW_BYTES}"))
    tg["law"].attrs["conventions"] = "\n".join(f"{law.name}: {law.convention}" for law in laws.LAWS.values()
                                               if any(t.model.law == law.name for t in tasks))
    tg.create_dataset("events_written", data=np.zeros(len(tasks), dtype=np.int64))
    for name, dtype in PROVENANCE_FIELDS.items():
        tg.create_dataset(name, shape=(len(tasks),), dtype=dtype, fillvalue=_FILL[dtype])
    tg.create_dataset("status", data=np.full(len(tasks), OPEN, dtype=np.int64))
    tg.create_dataset("error", shape=(len(tasks),), dtype=f"S{TEXT_BYTES}")
    tg.create_dataset("integrator", data=np.full(len(tasks), fixed_text(integrator_text), dtype=f"S{TEXT_BYTES}"))
    tg.create_dataset("branch_of", data=np.array([t.point if spinups else -1 for t in tasks], dtype=np.int64))
    if spinups:
        sg = h5.create_group("spinup")
        sg.create_dataset("point", data=np.array([t.point for t in spinups], dtype=np.int64))
        sg.create_dataset("spawn_key", data=np.array([t.index for t in spinups], dtype=np.int64))
        sg.create_dataset("N", data=np.array([t.model.N for t in spinups], dtype=np.int64))
    records = list(tasks) + spinups
    creep = np.array([carries_creep(t.model) for t in records], dtype=np.int8)
    sizes = np.array([2 * state_size(t.model.blocks, c) for t, c in zip(records, creep)], dtype=np.int64)
    offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    cp = h5.create_group("checkpoint")
    cp.create_dataset("state", shape=(int(sizes.sum()),), dtype=np.float64, fillvalue=np.nan,
                      dcpl=early_allocation())
    cp.create_dataset("offset", data=offset)
    cp.create_dataset("creep", data=creep)
    cp.create_dataset("commit", data=np.zeros((len(sizes), 2, NCOMMIT), dtype=np.int64))
    # metadata, written once here like the rest of the layout; under mpio every rank runs
    # this with the same values in the same order, as attribute writes are collective
    columns = {name: tg[name][...] for name in tables.RECORD}
    tg.create_dataset("record_crc", data=np.array(
        [tables.record_crc(k, {name: col[k] for name, col in columns.items()}) for k in range(len(tasks))],
        dtype=np.int64))
    _create_histories(h5, cfg, tasks)
    for name, entry in DATASETS.items():
        if name in h5:    # /spinup only with run.branch
            h5[name].attrs["description"] = description(entry)
    h5.attrs["tables_crc"] = fixed_digest(h5)


def _create_histories(h5, cfg, tasks):
    """/histories (histories.py), only where the run keeps event histories."""
    per_task, snapshots = cfg.output.history, cfg.output.history_snapshots
    if per_task == 0:
        return
    slots = len(tasks) * per_task
    blocks = max(t.model.blocks for t in tasks)
    g = h5.create_group(histories.GROUP)
    g.attrs["per_task"] = per_task
    g.attrs["snapshots"] = snapshots
    g.attrs["blocks"] = blocks
    for name in histories.SCALARS:
        g.create_dataset(name, data=np.full(slots, -1, dtype=np.int64))
    for name, shape, dtype in (("time", (slots, snapshots), np.float64), ("sliding", (slots, snapshots), np.int64),
                               ("velocity", (slots, snapshots, blocks), np.float64),
                               ("slip", (slots, snapshots, blocks), np.float64)):
        # never filled, like /events: only the snapshots written take space
        g.create_dataset(name, shape=shape, dtype=dtype, fillvalue=_FILL[dtype], fill_time="never",
                         dcpl=early_allocation())


def early_allocation():
    """Dataset creation properties: file space allocated at creation, so the file's layout
    (and its metadata) never changes afterwards (serial HDF5 would allocate at the first write)."""
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)
    return dcpl


def estimate_bytes(cfg, tasks):
    """An upper bound of the size of the catalog of `tasks` (what space.check_fits asks for)."""
    records = list(tasks) + spinup_points(cfg, tasks)
    data = (len(tasks) * cfg.run.events * sum(np.dtype(t).itemsize for t in EVENT_FIELDS.values())
            + 8 * sum(2 * state_size(t.model.blocks, carries_creep(t.model)) for t in records)   # checkpoint slots
            + len(records) * (8 * (2 * NCOMMIT + 1) + 1)                      # commit rows, offsets, creep
            + len(tasks) * (8 * (len(TASK_FIELDS) + len(PROVENANCE_FIELDS) + 5) + 2 * TEXT_BYTES + 2 * LAW_BYTES))
    data += histories.size_bound(cfg, tasks)
    metadata = 4096 * (len(DATASETS) + 4) + 2 * len(cfg.to_toml()) + 64 * 1024
    return int(data * 1.01) + metadata

