"""Regions (`analysis reduce --region`): the faults of a population pooled as one region observes them.

A region is the population of one point of a run's sweep (ensemble/population.py): its faults are the
tasks of that point, each with parameters of its own. Catalogs whose regions have the same law, the same
[model] values and the same distributions (text for text) pool into one region, as equal points do.

The window. A region observes its faults over one common time, not one common number of events: every
fault records run.events events, but a fault of few blocks has fewer events per unit of loading than a long
one. Fault f's window starts at the onset t0_f of its first recorded inertial event and spans W of the
plate's displacement: its rows (inertial events and creep episodes) with t0_f <= t < t0_f + W / nu. W is the
shortest span (t_last - t0_f) nu of the region's faults, or `--region-span` (which may not exceed it), so
that each fault contributes events in proportion to its rate. `--region-skip S` starts every window S (T nu)
later (the shortest span shrinks by S): a region's first and second halves, reduced apart, show whether the
transient was long enough. A recurrence is counted when both of its
events are in the window; a window cuts no event in two (an event is in when its onset is).

The transient. Each fault discarded the catalog's `transient` events before it recorded (run.transient,
10 events per block of the longest fault by default: more per block for every shorter one). A fault whose
discard is below what was measured to be needed, MEASURED_TRANSIENT_PER_BLOCK events per block of its own
N (docs/benchmarks.md; of a plane, per block of its N M), is named in a warning.

The bootstrap resamples faults (reduce._units: with at least MIN_UNITS faults; with fewer, the stretches
of every fault's window, as for a point of few seeds), from SeedSequence(--seed, spawn_key from the
region's text) (bootstrap_key).
"""
import hashlib

import numpy as np

from ensemble import filekind
from ensemble.config import MEASURED_TRANSIENT_PER_BLOCK, loads
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.sweep import sweep_points, task_list

from . import geometry
from .reduce import PARAMS


class RegionError(ValueError):
    """Catalogs that cannot be reduced as regions (no population, no window); exit 2 like bad options."""


def describe(model, draws):
    """The text that names a region: its law, its [model] values not drawn, and each drawn key's distribution."""
    drawn = dict(draws)
    fixed = [f"{name}={getattr(model, name)!r}" for name in model.__dataclass_fields__
             if name not in drawn and getattr(model, name) is not None]
    return " ".join(fixed) + "; " + "; ".join(f"{k} ~ {spec.to_toml()}" for k, spec in sorted(drawn.items()))


def label(draws):
    """The drawn keys in a few words, for legends and reports: "N: power 2 on [100, 1600]; b: uniform on [20, 50]"."""
    return "; ".join(f"{k}: {spec.short()}" for k, spec in sorted(dict(draws).items()))


def bootstrap_key(text):
    """The spawn key of a region's bootstrap generator: the 4 first 32-bit words of sha256(text)."""
    digest = hashlib.sha256(text.encode()).digest()
    return tuple(int.from_bytes(digest[i:i + 4], "little") for i in range(0, 16, 4))


def group(paths, configs, discarded, tasks, span=None, skip=0.0, partial=False):
    """Pool the tasks (merge.Inputs.tasks, every catalog's one after the other) into regions: set
    tasks["point"] to the region, add tasks["window_start"], ["window_end"] (model time) and return
    ([(params, rows)], spans {region: W}, warnings). discarded: the events each catalog's tasks discarded
    before recording (its attribute `transient`). skip: the windows start this far (T nu) after each fault's
    first onset (--region-skip: the later part of the record alone, e.g. to see that the transient is gone).
    partial: a reduction of unfinished runs; its faults with fewer than two inertial events are left out of
    `tasks` (said in a warning). params: {"region": text (describe), "region_label": its
    label, "law": law, and each of PARAMS: the value its faults share, NaN for a key drawn; on a plane its
    geometry, M and l_across (geometry.point_params)}."""
    warnings = []
    start, last = _onsets(paths, tasks)
    if partial and not np.all(last > start):
        kept = last > start
        warnings.append(f"{np.count_nonzero(~kept)} of {len(kept)} faults left out: fewer than two inertial events "
                        "recorded yet (a partial reduction)")
        for name in tasks:
            tasks[name] = tasks[name][kept]
        start, last = start[kept], last[kept]
    regions, texts = {}, []
    for c, text in enumerate(configs):
        cfg = loads(text)
        if cfg.population is None:
            raise RegionError(f"{paths[c]}: its run has no [population]; --region pools the faults of a population")
        names = [(describe(model, draws), label(draws)) for model, draws in sweep_points(cfg)]
        listed = task_list(cfg)
        for g in np.flatnonzero(tasks["catalog"] == c):
            name, short = names[listed[int(tasks["catalog_task"][g])].region]
            if name not in regions:
                regions[name] = []
                texts.append((name, short))
            regions[name].append(int(g))
    tasks["window_start"], tasks["window_end"] = start.copy(), np.full(len(start), np.nan)
    points, spans = [], {}
    for r, (name, short) in enumerate(texts):
        rows = sorted(regions[name], key=lambda g: (int(tasks["seed_entropy"][g]), int(tasks["spawn_key"][g])))
        tasks["point"][rows] = r
        own = (last[rows] - start[rows]) * tasks["nu"][rows] - skip
        shortest = int(np.argmin(own))
        where = f"{paths[tasks['catalog'][rows[shortest]]]} task {tasks['catalog_task'][rows[shortest]]}"
        if not own[shortest] > 0:
            raise RegionError(f"{where}: fewer than two inertial events recorded" + (f" after --region-skip {skip:g}"
                              if skip else "") + f", so no window (region {r}: {name})")
        if span is not None and span > own[shortest]:
            raise RegionError(f"--region-span {span:g}: {where} spans only {own[shortest]:.6g} (T nu)"
                              + (f" after --region-skip {skip:g}" if skip else "") + f" of region {r}")
        spans[r] = own[shortest] if span is None else span
        tasks["window_start"][rows] = start[rows] + skip / tasks["nu"][rows]
        tasks["window_end"][rows] = tasks["window_start"][rows] + spans[r] / tasks["nu"][rows]
        shared = {p: (float(tasks[p][rows[0]]) if np.all(tasks[p][rows] == tasks[p][rows[0]]) else np.nan)
                  for p in PARAMS}
        # (a population draws N, l and its law's keys only: its faults share their geometry, M and l_across)
        points.append(({**shared, "region": name, "region_label": short, "law": str(tasks["law"][rows[0]]),
                        **geometry.point_params(tasks, rows[0])}, rows))
        warnings += _transient_warnings(paths, discarded, tasks, rows, r)
    return points, spans, warnings


def _onsets(paths, tasks):
    """(first, last) onset times of every task's recorded inertial events (NaN without any)."""
    n = len(tasks["point"])
    first, last = np.full(n, np.nan), np.full(n, np.nan)
    for c, path in enumerate(paths):
        with filekind.reading(path, "the event catalog", CatalogError), reader.Reader(path) as cat:
            for g in np.flatnonzero(tasks["catalog"] == c):
                k = int(tasks["catalog_task"][g])
                t = cat.column(k, "t")[cat.column(k, "kind") == schema.KIND_EVENT]
                if len(t):
                    first[g], last[g] = t.min(), t.max()
    return first, last


def _transient_warnings(paths, discarded, tasks, rows, r):
    out = []
    for g in rows:
        shape, c = geometry.task_shape(tasks, g), int(tasks["catalog"][g])
        need = MEASURED_TRANSIENT_PER_BLOCK * shape.n_blocks
        size = f"N = {shape.N}" if shape.one_row else f"{shape.N} x {shape.M} blocks"
        if discarded[c] < need:
            out.append(f"region {r}: {paths[c]} task {tasks['catalog_task'][g]} ({size}) discarded "
                       f"{discarded[c]} events before it recorded, fewer than the {need:g} its transient may last "
                       f"({MEASURED_TRANSIENT_PER_BLOCK:g} per block)")
    return out
