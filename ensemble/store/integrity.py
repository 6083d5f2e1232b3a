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


def event_problems(ev, n_blocks, first_row=0, t_before=-np.inf):
    """Range checks of a run of one task's rows (dict of arrays starting at row `first_row`, after an
    inertial event at time t_before); returns what is wrong, naming the first bad row of each kind.

    Rows of kind 0 (inertial events) follow each other in time; a creep episode (kind 1) is a row when it
    ends, with the time it began, so it may come after events that began later: its time is not ordered.
    """
    epi, first, last, t, mu = ev["epicenter"], ev["first"], ev["last"], ev["t"], ev["mu"]
    kind, ending = ev["kind"], ev["ending"]
    inertial = kind == 0
    # the onset of the inertial event before each row (t_before for the first ones)
    before = np.concatenate([[t_before], np.where(inertial, t, -np.inf)[:-1]])
    previous = np.maximum.accumulate(before) if len(before) else before
    checks = (
        ((epi < 0) | (epi >= n_blocks), lambda i: f"epicenter {int(epi[i])} outside the chain of {n_blocks} blocks"),
        ((first < 0) | (last >= n_blocks) | (first > last),
         lambda i: f"slipped blocks {int(first[i])}..{int(last[i])} outside the chain of {n_blocks} blocks"),
        ((ev["n_slipped"] < 1) | (ev["n_slipped"] > n_blocks), lambda i: f"n_slipped {int(ev['n_slipped'][i])}"),
        (~np.isfinite(t), lambda i: f"time {float(t[i])}"),
        (~np.isfinite(mu), lambda i: f"magnitude {float(mu[i])}"),
        (~(ev["slip"] > 0) | ~(ev["duration"] >= 0),
         lambda i: f"slip {float(ev['slip'][i])}, duration {float(ev['duration'][i])}"),
        (inertial & (t < previous),
         lambda i: f"time {float(t[i])!r} before the event ahead of it ({float(previous[i])!r})"),
        (~(inertial | (kind == 1)), lambda i: f"kind {int(kind[i])}"),
        (~(ev["stress_drop"] > 0) & ~np.isnan(ev["stress_drop"]),
         lambda i: f"stress drop {float(ev['stress_drop'][i])}"),
        ((ev["n_onset"] < 0) | (ev["n_onset"] > n_blocks) | (ev["n_widest"] < 0) | (ev["n_widest"] > n_blocks),
         lambda i: f"nucleation's blocks {int(ev['n_onset'][i])}, {int(ev['n_widest'][i])}"),
        ((ev["t_spread"] < 0) | (ev["t_widest"] < 0) | np.isinf(ev["t_spread"]) | np.isinf(ev["t_widest"]),
         lambda i: f"nucleation's times {float(ev['t_spread'][i])}, {float(ev['t_widest'][i])}"),
        (np.where(inertial, ending != 0, (ending != 1) & (ending != 2)),
         lambda i: f"ending {int(ending[i])} of a row of kind {int(kind[i])}"),
    )
    return [f"event {first_row + int(np.argmax(flags))}: {what(int(np.argmax(flags)))}"
            for flags, what in checks if flags.any()]
