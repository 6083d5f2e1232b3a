"""The summary HDF5 written by `python -m analysis reduce`.

    /bins/mu, /bins/tnu                         bin edges
    /bins/creep_mu, /bins/creep_duration        bin edges of the creep episodes' mu and log10(duration nu)
    /tasks/*                                    the task tables of the catalogs, one after the other
                                                (in the order given), one row per task, with
    /tasks/catalog, /tasks/catalog_task         its catalog (index into the attribute `catalogs`)
                                                and its index in that catalog
    /tasks/point                                the point it pools into (row of /points)
    /tasks/catalog_point                        its point in its catalog
    /tasks/seed_entropy, /tasks/spawn_key       its random stream (for a task that has not finished,
                                                the one the runner uses: analysis/merge.py)
    /per_task/{mu, tnu, tnu_interior}           (tasks, stretches, bins) counts
    /per_task/numbers                           (tasks, stretches, 9) counts and sums (analysis.stats)
    /per_task/{creep_mu, creep_duration}        (tasks, stretches, bins) counts of the creep episodes
    /per_task/creep                             (tasks, stretches, 4) counts and sums of the slow side
    /points/{N, l, nu, <law keys>}              parameters of each point (first appearance order;
                                                the keys of every friction law, NaN if not its law's)
    /points/law                                 its friction law (two laws may share keys: aging, slip)
    /points/{geometry, M, l_across}             its geometry and the plane's shape (only where a task is not a
                                                chain: then /tasks/{geometry, M, l_across} too; a summary of
                                                chains is as before the plane)
    /points/method, /points/units               resampling used ("seeds", "faults" or "blocks") and unit count
    /points/{mu, tnu, tnu_interior}_density     (points, bins): estimate; *_lo, *_hi: interval
    /points/{creep_mu, creep_duration}_density  the same for the creep episodes (format 3)
    /points/numbers/<name>                      (points, 3): estimate, lo, hi (see reduce.NUMBERS)
    /points/peaks                               (points, max peaks, 3): T*nu position, lo, hi (NaN pad)
    /bins/seis_time, /bins/seis_distance        bin edges of the seismicity around large events (format 5)
    /per_task/{seis_pairs, seis_exposure}       (tasks, stretches, time x distance bins) its counts and exposures
    /per_task/seismicity                        (tasks, stretches, 3) its mainshocks and background
    /points/seismicity_rate                     (points, time bins, distance bins) its map
    attributes: format; catalogs (the catalogs' paths, in the order given: /tasks/catalog indexes
                them) and configs (their stored configs, same order); config (the one catalog's
                config, only when there is one); catalog (the catalog's path, or for several a
                short description of them, for titles); partial ("" or the one-line statement of
                an unfinished reduction: events reduced of expected, which catalogs); the options
                but the bins (STORED_OPTIONS: mu_c, window, b_cut, seis_near, seis_ring, seis_short,
                seis_long, bootstrap, level, blocks, seed)

The tasks of a point are its resampling units in the order of their streams, (seed_entropy,
spawn_key); its bootstrap draws from SeedSequence(seed, spawn_key from its parameters)
(merge.bootstrap_rng), so its numbers do not depend on which catalogs held its tasks or in
which order they were given.

`format` tells a summary from a catalog (ensemble/filekind.py); summaries written before it
existed are known by their attributes and groups. Format 3 adds the creep episodes (the slow side:
/bins/creep_*, /per_task/creep*, /points/creep_*, the creep statistic's numbers). Format 2
(GR b and its standard error, 9 per-task sums, peaks by prominence; catalogs, configs, partial and
the /tasks columns catalog, catalog_task and catalog_point) still reads, without those datasets
(it holds no creep statistic, statistics.holds: its creep episodes, if any, were not reduced); older ones do not: reduce
the catalogs again.

Format 6 adds checksums: every dataset a `crc32` attribute (CRC-32 of its name and values), the file an
`attrs_crc32` over its other attributes; read() checks them all and names the first that fails in one line
(SummaryError), so one flipped byte is never read as a number. Summaries of formats 5 to 2 read unchecked.

Every dataset carries a one-line `description` attribute (meaning, unit, shape) from the table
DATASETS below (`python -c "from analysis import summary; print(summary.schema())"` prints it),
so `h5dump -A` or any HDF5 viewer explains the file. A new dataset needs its line there
(tests/test_export.py fails on a dataset without one); summaries written before the attribute
existed read the same.
"""
import io
import os
import zlib

import h5py
import numpy as np

from ensemble import checks, filekind, space
from ensemble.store import schema as catalog_schema

from . import options, reduce
from .geometry import CHAIN
from .reduce import GEOMETRY_PARAMS, MIN_UNITS, NUMBERS, PARAMS
from .statistics import bin_names

FORMAT = filekind.SUMMARY_FORMAT_PREFIX + "6"   # 6: checksums (a `crc32` on every dataset, `attrs_crc32` over
# the file's attributes: seal, checked by read); a statistic added since (the rupture lengths and classes) adds its
# datasets to it, and a summary written before lacks them (statistics.holds: not shown). 5: the seismicity around
# large events (/bins/seis_*,
# /per_task/seis_*, /per_task/seismicity, /points/seismicity_rate, its numbers, the seis_* attributes). 4: the
# intervals statistic (/per_task/intervals, cv_tnu, mean_gap, cv_gap). 3: the creep episodes (bins, per-task
# counts and sums, densities, CREEP_NUMBERS). 2: GR b and its standard error, 9 per-task sums, peaks by
# prominence; several catalogs (catalogs, configs, partial, /tasks/catalog, catalog_task, catalog_point)
# formats 5, 4, 3 and 2 still read, without the datasets that came after them (a number a summary lacks is not shown)
# and without checksums
READS = (FORMAT, *(filekind.SUMMARY_FORMAT_PREFIX + n for n in "5432"))
CRC = "crc32"               # the attribute of every dataset of a FORMAT summary: _crc of its name and values
ATTRS_CRC = "attrs_crc32"   # the file's attribute: _attrs_crc of all the others

# Every dataset, one line each: (unit, shape, meaning), units as in ensemble/store/schema.py's DATASETS
# (T nu, the plate's displacement during a recurrence time, is a model length).
_POINTS = "(points,)"
_INTERVAL = "(points, 3): estimate, lo, hi (lo, hi: the bootstrap interval at `level`, NaN with one unit)"
_CURVE = "(points, {} bins)"   # the curve's variable
# the options a summary stores as attributes (its bins are /bins/<name>), declared by the statistics and the engine
STORED_OPTIONS = tuple(name for name, o in options.declared("reduce").items() if o.kind != "bins")
LAYOUT = reduce.LAYOUT   # the statistics (analysis/statistics/): their tables, curves and numbers
if LAYOUT.samples or LAYOUT.chain_bins:   # ragged per unit, or of a width per point: no /per_task dataset holds them
    raise ImportError(f"analysis/statistics: the summary stores no sample table nor bins of the chain's own "
                      f"({LAYOUT.samples + list(LAYOUT.chain_bins)}): give their statistic a set of its own (sets)")
CURVES = {   # name -> (its bins, its variable, whose variable, the density's unit), in the curves' order
    c.name: (LAYOUT.tables[c.table].bins, c.variable, c.whose, c.unit) for c in LAYOUT.curves}
NUMBER_MEANINGS = {n.name: (n.unit, n.meaning) for n in LAYOUT.numbers}   # in the order of reduce.NUMBERS
_BINS = {   # name -> (unit, what its edges bin): of the bins options (analysis/statistics/, Option)
    o.bins: (o.unit, f"{o.help.replace(' lo:hi:n', '').split(' (')[0]} (reduce {o.flag})")
    for o in options.declared("reduce").values() if o.kind == "bins"}


def _table_entry(name):
    """DATASETS' line of /per_task/<table>: from the statistics that declare it."""
    t = LAYOUT.tables[name]
    if t.bins:
        return (t.unit, f"(tasks, stretches, {' x '.join(bin_names(t))} bins)", t.meaning)
    columns = LAYOUT.columns[name]
    return (t.unit, f"(tasks, stretches, {len(columns)})",
            f"{', '.join(columns)} (analysis/statistics/) per task and stretch")


DATASETS = {
    **{f"bins/{name}": (unit, f"({name} bins + 1,)", f"edges of the {what}, half-open [lo, hi), the last one too")
       for name, (unit, what) in _BINS.items()},
    **{name: entry for name, entry in catalog_schema.DATASETS.items() if name.startswith("tasks/")},
    **{f"tasks/{name}": entry for name, entry in catalog_schema.READER_TASKS.items()},
    # the columns a summary of one or more catalogs (analysis/merge.py) sets or adds
    "tasks/point": ("index", "(tasks,)", "parameter point the task pools into (row of /points)"),
    "tasks/seed_entropy": ("1", "(tasks,)", "the task's stream is SeedSequence(seed_entropy, spawn_key=(spawn_key,)); "
                                            "for a task not finished, the run.seed of its catalog's config"),
    "tasks/spawn_key": ("index", "(tasks,)", "spawn key of the task's SeedSequence (for a task not finished, "
                                             "its index in its catalog, as the runner uses)"),
    "tasks/catalog": ("index", "(tasks,)", "catalog that holds the task (index into the attribute `catalogs`)"),
    "tasks/catalog_task": ("index", "(tasks,)", "the task's index in its catalog"),
    "tasks/catalog_point": ("index", "(tasks,)",
                            "the task's parameter point in its catalog (position in the product of its [sweep] lists)"),
    **{f"per_task/{name}": _table_entry(name) for name in LAYOUT.tables},
    **{f"points/{name}": (unit, _POINTS, f"{meaning}, of the point's tasks")
       for name, (unit, _, meaning) in ((n, catalog_schema.DATASETS[f"tasks/{n}"]) for n in PARAMS)},
    "points/law": ("text", _POINTS, "friction law of the point's tasks (a point is a law and its parameters)"),
    # where a task is of another geometry than the chain (analysis/geometry.py); a summary of chains holds none
    "points/geometry": ("text", _POINTS, "model.geometry of the point's tasks (a summary of chains alone holds none "
                                         "of these three)"),
    "points/M": ("count", _POINTS, "blocks across strike of the point's tasks (model.M; 1 on a chain); its blocks "
                                   "are N M"),
    "points/l_across": ("1", _POINTS, "spring stiffness across strike of the point's tasks (model.l_across; NaN on a "
                                      "chain)"),
    "points/method": ("text", _POINTS, "resampling units of the intervals: 'seeds' (the point's tasks, "
                                       f"when it has at least {MIN_UNITS}; 'faults' those of a region) or 'blocks' "
                                       "(the stretches of all its tasks)"),
    "points/units": ("count", _POINTS, "resampling units of the point"),
    # a regional reduction's (reduce --region, analysis/region.py): each point a region, its parameters those its
    # faults share (NaN where drawn); method 'faults' resamples the region's faults
    "points/region": ("text", _POINTS,
                      "the region: its law, its [model] values not drawn, each drawn key's distribution"),
    "points/region_label": ("text", _POINTS, "its drawn keys in a few words (legends, the report)"),
    "points/region_span": ("model length", _POINTS, "the span W of the region's window (T nu): every fault's rows "
                                                    "with t0 <= t < t0 + W / nu, t0 its first recorded onset"),
    "tasks/window_start": ("model time", "(tasks,)", "start of the fault's window: the onset of its first recorded "
                                                     "inertial event (regional reduction)"),
    "tasks/window_end": ("model time", "(tasks,)", "end of the fault's window, excluded (regional reduction)"),
    **{f"points/{name}_{part}": (unit, _CURVE.format(variable), f"{what} of the {variable} of {whose}")
       for name, (_, variable, whose, unit) in CURVES.items()
       for part, what in (("density", "probability density"), ("lo", "lower interval end of the density"),
                          ("hi", "upper interval end of the density"))},
    **{f"points/numbers/{name}": (unit, _INTERVAL, meaning) for name, (unit, meaning) in NUMBER_MEANINGS.items()},
    **{f"points/{name}": entry for st in LAYOUT.statistics for name, entry in st.extra_datasets.items()},
}


def schema():
    """The table of datasets as text, one line per dataset."""
    return catalog_schema.schema(DATASETS)


def _describe(h5):
    """Give every dataset its line of DATASETS as `description` (one missing there gets none)."""
    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and name in DATASETS:
            obj.attrs["description"] = catalog_schema.description(DATASETS[name])
    h5.visititems(visit)


def _canonical(value):
    """The bytes a checksum covers of a dataset's values or an attribute, as h5py reads them back (text as
    UTF-8 items, whatever the container h5py gives it in)."""
    a = np.asarray(value)
    if a.dtype.kind in "OSU":
        items = [x.decode("utf-8", "replace") if isinstance(x, bytes) else str(x) for x in a.ravel()]
        return f"text{a.shape}".encode() + "\0".join(items).encode()
    return f"{a.dtype.str}{a.shape}".encode() + np.ascontiguousarray(a).tobytes()


def _crc(name, value):
    return zlib.crc32(name.encode() + b"\0" + _canonical(value))


def _attrs_crc(attrs):
    """Of every attribute of the file but ATTRS_CRC itself, in name order."""
    crc = 0
    for key in sorted(k for k in attrs if k != ATTRS_CRC):
        crc = zlib.crc32(key.encode() + b"\0" + _canonical(attrs[key]), crc)
    return crc


def seal(h5):
    """Every dataset's CRC from its values as read back, then the attributes' (read() checks them); also for a
    test that edits a summary by hand."""
    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            obj.attrs[CRC] = _crc(name, obj[...])
    h5.visititems(visit)
    h5.attrs[ATTRS_CRC] = _attrs_crc(h5.attrs)


class SummaryError(RuntimeError):
    """A summary that cannot be written or read; the message names the file."""


def describe_sources(paths):
    """The catalogs of a summary in a few words: the path of one; up to three listed; more counted."""
    paths = [str(p) for p in paths]
    if len(paths) <= 3:
        return ", ".join(paths)
    return f"{paths[0]} ... {paths[-1]} ({len(paths)} catalogs)"


def _source_attrs(inputs):
    attrs = {"catalog": describe_sources(inputs.paths), "catalogs": list(inputs.paths),
             "configs": list(inputs.configs), "partial": inputs.partial}
    if len(inputs.paths) == 1:
        attrs["config"] = inputs.configs[0]
    return attrs


def write(path, inputs, per_task, points, opt, force=False):
    """inputs: analysis.merge.Inputs (the catalogs and their task table)."""
    checks.output(path, force=force, what="summary")   # again: one could have appeared during the work
    tmp = str(path) + ".partial"
    checks.output(tmp, force=True, what="summary")      # (a link there would be written through)
    # built in memory, then written as plain bytes with its blocks reserved first (space.write_file): a full disk
    # is one line, where an HDF5 write failing on it could crash the process when the file is closed
    image = io.BytesIO()
    with h5py.File(image, "w") as h5:
        h5.attrs.update({"format": FORMAT, **_source_attrs(inputs), **opt.stored()})
        edges = reduce.bin_edges(opt)
        for name, values in edges.items():
            h5[f"bins/{name}"] = values
        for name, values in inputs.tasks.items():
            # text columns (a task's error, its integrator) are stored as UTF-8 bytes
            h5[f"tasks/{name}"] = np.char.encode(values) if values.dtype.kind == "U" else values
        order = sorted(per_task)
        for name in reduce.UNIT_ARRAYS:   # (compressed: mostly zeros, e.g. the seismicity's maps of every stretch)
            h5.create_dataset(f"per_task/{name}", data=np.stack([per_task[k][name] for k in order]),
                              compression="gzip", compression_opts=4, shuffle=True)
        for name in PARAMS:
            h5[f"points/{name}"] = np.array([p["params"][name] for p in points])
        h5["points/law"] = np.array([p["params"]["law"] for p in points], dtype="S")
        if "geometry" in inputs.tasks:   # a plane among the tasks (merge.read): every point says its shape
            h5["points/geometry"] = np.array([p["params"].get("geometry", CHAIN) for p in points], dtype="S")
            h5["points/M"] = np.array([p["params"].get("M", 1) for p in points], dtype=np.int64)
            h5["points/l_across"] = np.array([p["params"].get("l_across", np.nan) for p in points], dtype=np.float64)
        if inputs.spans:    # a regional reduction (analysis/region.py)
            h5["points/region"] = np.array([p["params"]["region"].encode() for p in points], dtype="S")
            h5["points/region_label"] = np.array([p["params"]["region_label"].encode() for p in points], dtype="S")
            h5["points/region_span"] = np.array([inputs.spans[i] for i in range(len(points))])
        h5["points/method"] = np.array([p["method"] for p in points], dtype="S")
        h5["points/units"] = np.array([p["units"] for p in points])
        start = 0
        for name, (bins, *_) in CURVES.items():   # the curves one after the other, in this order
            n = len(edges[bins]) - 1
            for suffix, j in (("density", 0), ("lo", 1), ("hi", 2)):
                h5[f"points/{name}_{suffix}"] = np.stack([p["curves"][j][start:start + n] for p in points])
            start += n
        for i, name in enumerate(NUMBERS):
            h5[f"points/numbers/{name}"] = np.stack([p["numbers"][i] for p in points])
        for st in LAYOUT.statistics:   # each statistic's extras, NaN-padded to the largest of the points'
            for name in st.extra_datasets:
                h5[f"points/{name}"] = _padded([np.asarray(p[name], dtype=float) for p in points])
        _describe(h5)
        seal(h5)
    try:
        space.write_file(tmp, image.getbuffer(), "the summary")
    except OSError as err:
        raise SummaryError(f"{tmp}: cannot write the summary ({err.strerror or err})") from None
    os.replace(tmp, path)


def _padded(arrays):
    """(points, ...) of arrays of one rank, each padded with NaN to the largest extent (at least 1) of every axis."""
    shape = tuple(max([a.shape[d] for a in arrays] + [1]) for d in range(arrays[0].ndim))
    out = np.full((len(arrays), *shape), np.nan)
    for i, a in enumerate(arrays):
        out[(i, *(slice(0, n) for n in a.shape))] = a
    return out


class Read(dict):
    """A summary as read: {dataset path: array, "attrs": {name: value}}. Asking for a dataset (or, in "attrs", an
    attribute) the file does not hold raises SummaryError naming the file and what is missing, one line for the
    commands (a summary of another version, or damaged), where a KeyError's traceback would be."""

    def __init__(self, path, items=(), what="dataset"):
        super().__init__(items)
        self.path, self.what = path, what

    def __missing__(self, key):
        raise SummaryError(f"{self.path}: no {self.what} {key!r} in this summary (written by another version, or "
                           f"damaged); reduce the catalogs again")


def read(path):
    """Summary -> Read: a dict of arrays and attributes (see Read)."""
    filekind.require(path, "summary", SummaryError)
    out = Read(path)
    with filekind.reading(path, "the reduction summary", SummaryError):
        with h5py.File(path, "r") as h5:
            sealed = h5.attrs.get("format") == FORMAT
            damaged, sealed_datasets = [], []

            def visit(name, obj):
                if isinstance(obj, h5py.Dataset):
                    out[name] = obj[...]
                    want = obj.attrs.get(CRC)
                    if want is not None:
                        sealed_datasets.append(name)
                    if sealed and (want is None or int(want) != _crc(name, out[name])):
                        damaged.append(name)
            h5.visititems(visit)
            out["attrs"] = Read(path, {k: h5.attrs[k] for k in h5.attrs}, "attribute")
            if sealed and (ATTRS_CRC not in h5.attrs or int(h5.attrs[ATTRS_CRC]) != _attrs_crc(h5.attrs)):
                damaged.append("its attributes")
            if not sealed and sealed_datasets:   # checksums in a file that says it is of an older format
                damaged.append("its format attribute")
        if damaged:
            raise SummaryError(f"{path}: {damaged[0]} fails its checksum"
                               + (f" (and {len(damaged) - 1} more)" if len(damaged) > 1 else "")
                               + ": the summary is damaged; reduce the catalogs again")
        if out["attrs"].get("format") not in READS:
            raise SummaryError(f"{path}: summary format {out['attrs'].get('format', '(none)')}, this version "
                               f"reads {' and '.join(READS)}; reduce the catalog again")
        out["points/method"] = np.array([m.decode() for m in out["points/method"]])
        for name in ("points/region", "points/region_label", "points/geometry"):
            if name in out:
                out[name] = np.array([x.decode() for x in out[name]])
    for name in PARAMS:   # a summary from before the friction-law registry: aging points, no other keys
        out.setdefault(f"points/{name}", np.full(len(out["points/N"]), np.nan))
    if "points/law" in out:
        out["points/law"] = np.array([law.decode() for law in out["points/law"]])
    out["points/law"] = point_laws(out)
    return out


def point_geometries(s):
    """(points,) the geometry of each point of summary `s` (read): chains where it holds none."""
    return np.asarray(s["points/geometry"]) if "points/geometry" in s else np.full(len(s["points/N"]), CHAIN)


def point_blocks(s):
    """(points,) the number of blocks of each point of summary `s` (read): N, or N M on a plane."""
    M = s["points/M"] if "points/M" in s else 1
    return (np.asarray(s["points/N"]) * M).astype(np.int64)


def point_keys(s):
    """The parameters that tell the points of summary `s` apart: reduce.PARAMS, and the plane's M and l_across
    where it holds a plane (the geometry's name is said as the law is: report.point_label)."""
    return list(PARAMS) + [k for k in GEOMETRY_PARAMS if k != "geometry" and f"points/{k}" in s]


def point_laws(s):
    """(points,) the friction law of each point of summary `s` (read). A summary from before the law
    was part of a point holds none: Carlson-Langer where alpha is set, else the aging law (the slip
    law, which shares the aging law's keys, came with the law in the point)."""
    if "points/law" in s:
        return np.asarray(s["points/law"])
    alpha = s.get("points/alpha", np.full(len(s["points/N"]), np.nan))
    return np.where(np.isnan(alpha), "aging", "carlson-langer")


def point_units(s, i, merge=1):
    """Point i's resampling units of summary `s` (read): (mu edges, counts (tasks, stretches, bins) of R(mu),
    inertial events (tasks, stretches)). A region's tasks are its faults. merge: bins of that many of the
    summary's (ValueError where they do not divide)."""
    edges = s["bins/mu"][::merge]
    tasks = np.flatnonzero(s["tasks/point"] == i)
    counts = s["per_task/mu"][tasks]
    events = s["per_task/numbers"][tasks][:, :, reduce.LAYOUT.column("numbers", "n_events")]
    if merge > 1:
        if (len(s["bins/mu"]) - 1) % merge:
            raise ValueError(f"{len(s['bins/mu']) - 1} bins of mu do not merge by {merge}")
        counts = counts.reshape(*counts.shape[:-1], len(edges) - 1, merge).sum(axis=-1)
    return edges, counts, events
