"""Checksums and range checks of what a catalog stores (pure numpy and zlib, no HDF5).

Three things are checksummed (CRC-32, which catches any burst error up to 32 bits
and a one-byte flip with certainty):

- a checkpoint slot: the packed state (force, psi, since, clock) as float64 bytes;
- a task's events: one running CRC per column over the task's rows in order, so a
  catalog can be verified column by column however its batches were cut;
- a commit row: its own fields with the task and slot it belongs to, so a row that
  is torn, flipped or copied to another place is recognised.
"""
import zlib

import numpy as np


def crc(data, start=0):
    """CRC-32 of an array's bytes (C order), continuing from `start`."""
    return zlib.crc32(np.ascontiguousarray(data).view(np.uint8), start)


class EventCrc:
    """Running CRCs of one task's event columns (in a fixed column order) and their row count."""

    def __init__(self, names):
        self.names = tuple(names)
        self.values = [0] * len(self.names)
        self.rows = 0

    def update(self, batch):
        n = len(batch[self.names[0]])
        for k, name in enumerate(self.names):
            if len(batch[name]) != n:
                raise ValueError(f"event column {name} has {len(batch[name])} rows, expected {n}")
            self.values[k] = crc(batch[name], self.values[k])
        self.rows += n

    def combined(self):
        """One number for the commit row: the CRC of the per-column CRCs."""
        return crc(np.asarray(self.values, dtype=np.int64))


def commit_crc(task, slot, fields):
    """CRC of a commit row's fields (everything but the CRC itself), bound to its task and slot."""
    return crc(np.asarray([task, slot, *fields], dtype=np.int64))


def event_problems(ev, n_blocks, per_task_rows=None):
    """Range checks of one task's events (dict of arrays); returns a list of what is wrong."""
    problems = []
    epi, first, last = ev["epicenter"], ev["first"], ev["last"]
    if np.any((epi < 0) | (epi >= n_blocks)):
        problems.append("epicenter outside [0, N)")
    if np.any((first < 0) | (last >= n_blocks) | (first > last)):
        problems.append("first/last outside [0, N) or first > last")
    if np.any((ev["n_slipped"] < 1) | (ev["n_slipped"] > n_blocks)):
        problems.append("n_slipped outside [1, N]")
    if not (np.all(np.isfinite(ev["t"])) and np.all(np.isfinite(ev["mu"]))
            and np.all(ev["slip"] > 0) and np.all(ev["duration"] >= 0)):
        problems.append("non-finite time or magnitude, or non-positive slip")
    if len(ev["t"]) > 1 and np.any(np.diff(ev["t"]) < 0):
        problems.append("onset times decrease")
    return problems
