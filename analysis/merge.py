"""Catalogs -> the one task table a reduction works on: which tasks pool, in which order, and
whether the input is complete.

A trajectory is its random stream (seed_entropy, spawn_key) together with its parameters
(N, l, nu, a, b, c). The runner records the stream of a task when the task finishes; for a task
that has not finished it is the stream the runner uses, SeedSequence(run.seed of the catalog's
config, spawn_key=(task index,)) (ensemble/run/tasks.py), and the summary stores it so.

- Points. Tasks with exactly equal parameters pool into one parameter point, whichever catalog
  they come from (on a plane, model.geometry with its M and l_across are parameters too, so two
  planes of other shapes, or a plane and a chain, never pool: analysis/geometry.py); points are
  numbered in the order of first appearance (catalogs in the order given, tasks in catalog order).
- Order inside a point. The tasks of a point are ordered by their stream, (seed_entropy,
  spawn_key); these are the resampling units in that order. With `bootstrap_rng`, which depends
  on the --seed and the point's parameters only, a point's numbers and intervals do not depend on
  the order or grouping of the catalogs that hold its tasks, nor on the other points.
- The same trajectory twice (two tasks of one point with the same stream) is refused.
- Unfinished runs (a *.partial catalog, or tasks not finished or with fewer events than
  events_per_task) are refused unless allowed; then `partial` says how much is missing.
"""
import os
from dataclasses import dataclass

import numpy as np

from ensemble import filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.config import loads

from . import geometry
from . import region as regions
from .reduce import LAYOUT, PARAMS, reduce_tasks


def _known_geometry(path, tasks):
    """A catalog of a geometry the analysis does not know (analysis/geometry.py) is refused in one line."""
    other = sorted({str(name) for name in tasks["geometry"]} - set(geometry.GEOMETRIES))
    if other:
        raise MergeError(f"{path}: a catalog of model.geometry = {other[0]!r}; the analysis reads "
                         f"{', '.join(geometry.GEOMETRIES)} (those on a grid: Geometry.grid, ensemble/model/geometry/)")


def _chains_without_geometry(tables):
    """Where every task is a chain, the geometry's columns (a chain's defaults) are left out of the task table,
    so that a summary of chains is the one of before; with a plane among them, every task keeps them."""
    if all(set(map(str, t["geometry"])) <= {geometry.CHAIN} for t in tables):
        for tasks in tables:
            for name in schema.GEOMETRY_TASKS:
                tasks.pop(name, None)


class MergeError(ValueError):
    """Catalogs that cannot be reduced together (the same trajectory twice); exit 2 like bad options."""


@dataclass
class Inputs:
    """The catalogs of one reduction, as one task table.

    tasks: the catalogs' task tables one after the other (catalog order), with
      catalog, catalog_task   index of the task's catalog in `paths`, the task's index in it
      catalog_point           the task's point in its catalog
      point                   the task's point in the summary (index into `points`)
      seed_entropy, spawn_key its stream (filled in for tasks that have not finished)
    points: [(parameters {name: value, "law": its law}, [rows of `tasks` in stream order])], first
                            appearance order; of regions (read(region=True), analysis/region.py)
                            [({"region": its text, "law": its law}, [rows of its faults])], and tasks has
      window_start, window_end  each fault's window (model time)
    partial: "" for finished runs, else the one-line statement of what is missing
    spans: {region: its window's span W (T nu)} (regions only)
    warnings: one line each, said before the summary is written (regions: a transient too short)
    """
    paths: list
    configs: list
    events_per_task: list
    tasks: dict
    points: list
    partial: str
    spans: dict = None
    warnings: list = ()


def bootstrap_rng(seed, params):
    """The bootstrap generator of the point with these parameters:
    SeedSequence(seed, spawn_key=(N, bits(l), bits(nu), bits(x) for each of its law's keys x in
    PARAMS order)), where bits(x) is the IEEE-754 binary64 pattern of x as an unsigned integer (for
    the aging law: bits(a), bits(b), bits(c)). Keys of other laws (NaN) are left out. A point of another
    geometry than the chain appends geometry.spawn_key (CRC-32 of its name, bits(M), bits(l_across)). A region's:
    SeedSequence(seed, spawn_key=region.bootstrap_key(its text))."""
    if "region" in params:
        return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=regions.bootstrap_key(params["region"])))
    key = [int(params["N"])] + [int(np.float64(params[name]).view(np.uint64)) for name in PARAMS[1:]
                                if not np.isnan(params[name])] + geometry.spawn_key(params)
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=tuple(key)))


def _streams(tasks, config_text):
    """(seed_entropy, spawn_key) of every task, as recorded or as the runner will record them."""
    entropy, key = tasks["seed_entropy"].copy(), tasks["spawn_key"].copy()
    unrecorded = (entropy < 0) | (key < 0)
    if unrecorded.any():
        root = loads(config_text).run.seed
        entropy[unrecorded] = root
        key[unrecorded] = np.flatnonzero(unrecorded)
    return entropy, key


def _unfinished(path, tasks, per_task):
    """Unfinished tasks of a catalog: (count, True if the file is a run's *.partial)."""
    open_ = (tasks["status"] != schema.FINISHED) | (tasks["events_written"] < per_task)
    return int(np.count_nonzero(open_)), str(path).endswith(".partial")


def read(paths, allow_partial=False, region=False, span=None, skip=0.0):
    """Inputs of the catalogs at `paths`; every check is made here, before any work. region: pool the faults
    of each population into its region over a common window (analysis/region.py), of span `span` (T nu) if
    given, else the shortest of its faults', each window starting `skip` (T nu) after its fault's first onset."""
    paths = [str(p) for p in paths]
    for i, a in enumerate(paths):
        filekind.require(a, "catalog", CatalogError)
        for b in paths[:i]:
            if os.path.samefile(a, b):
                raise MergeError(f"{a} is given twice (also as {b}): give each catalog once")
    tables, configs, per_tasks, unfinished, discarded = [], [], [], [], []
    for path in paths:
        with filekind.reading(path, "the event catalog", CatalogError):
            per_task, tasks, attrs = reader.read_tasks(path)
        _known_geometry(path, tasks)
        tasks["seed_entropy"], tasks["spawn_key"] = _streams(tasks, attrs["config"])
        tables.append(tasks)
        configs.append(str(attrs["config"]))
        per_tasks.append(int(per_task))
        discarded.append(int(attrs.get("transient", 0)))
        unfinished.append(_unfinished(path, tasks, per_task))
    _chains_without_geometry(tables)
    partial = _partial_statement(paths, tables, per_tasks, unfinished)
    if partial and not allow_partial:
        path, tasks, (n_open, named) = next((p, t, u) for p, t, u in zip(paths, tables, unfinished)
                                            if u[0] or u[1])
        what = f"{n_open} of {len(tasks['point'])} tasks unfinished" if n_open else "named *.partial"
        raise CatalogError(
            f"{path} is an unfinished run ({what}); continue it with `python -m ensemble resume "
            f"{path.removesuffix('.partial')}`, or reduce what it holds with --partial")
    tasks = _concatenate(tables)
    if region:
        points, spans, warnings = regions.group(paths, configs, discarded, tasks, span, skip, bool(partial))
        return Inputs(paths, configs, per_tasks, tasks, points, partial, spans, warnings)
    return Inputs(paths, configs, per_tasks, tasks, _points(paths, tasks), partial)


def _concatenate(tables):
    out = {}
    for name in tables[0]:
        out[name] = np.concatenate([t[name] for t in tables])
    out["catalog"] = np.concatenate([np.full(len(t["point"]), i, dtype=np.int64) for i, t in enumerate(tables)])
    out["catalog_task"] = np.concatenate([np.arange(len(t["point"]), dtype=np.int64) for t in tables])
    out["catalog_point"] = out["point"].copy()
    return out


def _points(paths, tasks):
    """Pool the rows of `tasks` by friction law, geometry and exact parameters; set tasks["point"]; refuse
    repeated streams. Two laws may share keys (aging and slip: a, b, c), so the law is part of a point; so is a
    plane's shape (geometry.point_key: nothing on a chain)."""
    where = {}
    for g in range(len(tasks["point"])):
        # by bit pattern: keys of another law are NaN, which equals nothing, itself included
        law = law_name(tasks["law"][g])
        bits = (law, *(np.float64(tasks[name][g]).view(np.uint64).item() for name in PARAMS),
                *geometry.point_key(tasks, g))
        where.setdefault(bits, (tuple(tasks[name][g].item() for name in PARAMS), law, geometry.point_params(tasks, g),
                                []))[3].append(g)
    points = []
    for i, (key, law, shape, rows) in enumerate(where.values()):
        rows.sort(key=lambda g: (int(tasks["seed_entropy"][g]), int(tasks["spawn_key"][g])))
        for a, b in zip(rows, rows[1:]):
            stream = (int(tasks["seed_entropy"][a]), int(tasks["spawn_key"][a]))
            if stream == (int(tasks["seed_entropy"][b]), int(tasks["spawn_key"][b])):
                def task(g):
                    return f"{paths[tasks['catalog'][g]]} task {tasks['catalog_task'][g]}"
                raise MergeError(
                    f"{task(a)} and {task(b)} are the same trajectory (seed_entropy {stream[0]}, "
                    f"spawn_key {stream[1]}, " + ", ".join(f"{n} = {v:g}" for n, v in zip(PARAMS, key) if v == v)
                    + "): give each trajectory once")
        tasks["point"][rows] = i
        points.append(({**dict(zip(PARAMS, key)), "law": law, **shape}, rows))
    return points


def law_name(law):
    """A task's friction law as text (the catalogs store it as bytes)."""
    return law.decode() if isinstance(law, bytes) else str(law)


def _partial_statement(paths, tables, per_tasks, unfinished):
    if not any(n or named for n, named in unfinished):
        return ""
    written = sum(int(t["events_written"].sum()) for t in tables)
    expected = sum(len(t["point"]) * p for t, p in zip(tables, per_tasks))
    share = f" ({100 * written / expected:.1f}%)" if expected else ""
    which = [f"{p} ({n} of {len(t['point'])} tasks unfinished)" if n else f"{p} (all tasks finished)"
             for p, t, (n, named) in zip(paths, tables, unfinished) if n or named]
    return (f"PARTIAL reduction of unfinished runs: {written} of {expected} events{share}; "
            + ", ".join(which))


def reduce_share(inputs, rows, opt, layout=LAYOUT):
    """The tables (reduce.reduce_task) of the given rows of inputs.tasks (one rank's share), keyed by row;
    layout: the statistics reduced (the summary's, or a set's: statistics.of)."""
    out = {}
    for c, path in enumerate(inputs.paths):
        mine = [g for g in rows if inputs.tasks["catalog"][g] == c]
        if mine:
            windows = ({int(inputs.tasks["catalog_task"][g]):
                        (inputs.tasks["window_start"][g], inputs.tasks["window_end"][g])
                        for g in mine} if "window_start" in inputs.tasks else None)
            local = reduce_tasks(path, [int(inputs.tasks["catalog_task"][g]) for g in mine], opt, layout, windows)
            out.update({g: local[int(inputs.tasks["catalog_task"][g])] for g in mine})
    return out
