"""The summary HDF5 written by `python -m analysis reduce`.

    /bins/mu, /bins/tnu                         bin edges
    /tasks/*                                    the catalog's task table
    /per_task/{mu, tnu, tnu_interior}           (tasks, stretches, bins) counts
    /per_task/numbers                           (tasks, stretches, 9) counts and sums (analysis.stats)
    /points/{N, l, nu, a, b, c}                 parameters of each point
    /points/method, /points/units               resampling used ("seeds" or "blocks") and unit count
    /points/{mu, tnu, tnu_interior}_density     (points, bins): estimate; *_lo, *_hi: interval
    /points/numbers/<name>                      (points, 3): estimate, lo, hi (see reduce.NUMBERS)
    /points/peaks                               (points, max peaks, 3): T*nu position, lo, hi (NaN pad)
    attributes: format, config (the catalog's), catalog, mu_c, window, b_cut, bootstrap, level,
                blocks, seed

`format` tells a summary from a catalog (ensemble/filekind.py); summaries written before it
existed are known by their attributes and groups.

Every dataset carries a one-line `description` attribute (meaning, unit, shape) from the table
DATASETS below (`python -c "from analysis import summary; print(summary.schema())"` prints it),
so `h5dump -A` or any HDF5 viewer explains the file. A new dataset needs its line there
(tests/test_export.py fails on a dataset without one); summaries written before the attribute
existed read the same.
"""
import os

import h5py
import numpy as np

from ensemble import catalog, filekind

from . import stats
from .reduce import NUMBERS, PARAMS

FORMAT = filekind.SUMMARY_FORMAT_PREFIX + "2"   # 2: GR b and its standard error, 9 per-task sums, peaks by prominence

# Every dataset, one line each: (unit, shape, meaning), units as in ensemble/catalog.py's DATASETS
# (T nu, the plate's displacement during a recurrence time, is a model length).
_POINTS = "(points,)"
_INTERVAL = "(points, 3): estimate, lo, hi (lo, hi: the bootstrap interval at `level`, NaN with one unit)"
_CURVE = "(points, {} bins)"   # the curve's variable
CURVES = {   # name -> (its bins, its variable, whose variable, the density's unit)
    "mu": ("mu", "mu", "all events", "1/mu"),
    "tnu": ("tnu", "T nu", "all recurrences", "1/model length"),
    "tnu_interior": ("tnu", "T nu", "the recurrences starting at an interior event (boundary false)",
                     "1/model length"),
}
NUMBER_MEANINGS = {   # name -> (unit, meaning), in the order of reduce.NUMBERS
    "n_events": ("count", "events"),
    "n_large": ("count", "large events (mu >= mu_c)"),
    "fraction_large": ("1", "fraction of the events with mu >= mu_c"),
    "n_recurrences": ("count", "recurrences: large events closed by a later one within `window` blocks"),
    "mean_tnu": ("model length", "mean T nu of all recurrences"),
    "mode_tnu": ("model length", "centre of the highest T nu bin"),
    "mean_tnu_interior": ("model length", "mean T nu of the recurrences starting at an interior event"),
    "gr_b": ("1", "Aki's maximum-likelihood Gutenberg-Richter b (not the model's b) above mu = b_cut"),
    "gr_b_se": ("1", "Shi & Bolt standard error of gr_b (assumes independent events; trust the interval)"),
    "ks_gr": ("1", "Kolmogorov-Smirnov distance of the binned mu >= b_cut from the fitted GR law"),
}
DATASETS = {
    "bins/mu": ("log10 model length", "(mu bins + 1,)",
                "edges of the magnitude bins, half-open [lo, hi), the last one too"),
    "bins/tnu": ("model length", "(T nu bins + 1,)", "edges of the T nu bins, half-open [lo, hi), the last one too"),
    **{name: entry for name, entry in catalog.DATASETS.items() if name.startswith("tasks/")},
    **{f"tasks/{name}": entry for name, entry in catalog.READER_TASKS.items()},
    "per_task/mu": ("count", "(tasks, stretches, mu bins)", "events per magnitude bin, per task and stretch"),
    "per_task/tnu": ("count", "(tasks, stretches, T nu bins)",
                     "recurrences per T nu bin, per task and stretch of their starting event"),
    "per_task/tnu_interior": ("count", "(tasks, stretches, T nu bins)",
                              "the same for the recurrences starting at an interior event"),
    "per_task/numbers": ("count or sum", f"(tasks, stretches, {stats.N_STATS})",
                         "n_events, n_large, n_rec, sum_tnu, n_rec_int, sum_tnu_int, n_gr, sum_mu_gr, "
                         "sum_mu2_gr (analysis/stats.py) per task and stretch"),
    **{f"points/{name}": (unit, _POINTS, f"{meaning}, of the point's tasks")
       for name, (unit, _, meaning) in ((n, catalog.DATASETS[f"tasks/{n}"]) for n in PARAMS)},
    "points/method": ("text", _POINTS, "resampling units of the intervals: 'seeds' (the point's tasks) or "
                                       "'blocks' (stretches of its one task)"),
    "points/units": ("count", _POINTS, "resampling units of the point"),
    **{f"points/{name}_{part}": (unit, _CURVE.format(variable), f"{what} of the {variable} of {whose}")
       for name, (_, variable, whose, unit) in CURVES.items()
       for part, what in (("density", "probability density"), ("lo", "lower interval end of the density"),
                          ("hi", "upper interval end of the density"))},
    **{f"points/numbers/{name}": (unit, _INTERVAL, meaning) for name, (unit, meaning) in NUMBER_MEANINGS.items()},
    "points/peaks": ("model length", "(points, most peaks, 3): position, lo, hi; NaN rows pad",
                     "recurrence peaks of the T nu histogram, highest first (analysis/stats.py find_peaks)"),
}


def schema():
    """The table of datasets as text, one line per dataset."""
    return catalog.schema(DATASETS)


def _describe(h5):
    """Give every dataset its line of DATASETS as `description` (one missing there gets none)."""
    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and name in DATASETS:
            obj.attrs["description"] = catalog.description(DATASETS[name])
    h5.visititems(visit)


class SummaryError(RuntimeError):
    """A summary that cannot be written or read; the message names the file."""


def write(path, source, attrs_in, tasks, per_task, points, opt, force=False):
    if os.path.exists(path) and not force:
        raise SummaryError(f"{path}: summary exists (use --force to overwrite it)")
    n_mu, n_tnu = len(opt.mu_edges) - 1, len(opt.tnu_edges) - 1
    tmp = str(path) + ".partial"
    with h5py.File(tmp, "w") as h5:
        h5.attrs.update({"format": FORMAT, "config": attrs_in["config"], "catalog": str(source),
                         "mu_c": opt.mu_c, "window": opt.window, "b_cut": opt.b_cut,
                         "bootstrap": opt.bootstrap, "level": opt.level, "blocks": opt.blocks,
                         "seed": opt.seed})
        h5["bins/mu"] = opt.mu_edges
        h5["bins/tnu"] = opt.tnu_edges
        for name, values in tasks.items():
            # text columns (a task's error, its integrator) are stored as UTF-8 bytes
            h5[f"tasks/{name}"] = np.char.encode(values) if values.dtype.kind == "U" else values
        order = sorted(per_task)
        for name in ("mu", "tnu", "tnu_interior", "numbers"):
            h5[f"per_task/{name}"] = np.stack([getattr(per_task[k], name) for k in order])
        for name in PARAMS:
            h5[f"points/{name}"] = np.array([p["params"][name] for p in points])
        h5["points/method"] = np.array([p["method"] for p in points], dtype="S")
        h5["points/units"] = np.array([p["units"] for p in points])
        for i, name in enumerate(("mu", "tnu", "tnu_interior")):
            lo_idx = [0, n_mu, n_mu + n_tnu][i]
            n = [n_mu, n_tnu, n_tnu][i]
            for suffix, j in (("density", 0), ("lo", 1), ("hi", 2)):
                key = f"points/{name}_density" if suffix == "density" else f"points/{name}_{suffix}"
                h5[key] = np.stack([p["curves"][j][lo_idx:lo_idx + n] for p in points])
        for i, name in enumerate(NUMBERS):
            h5[f"points/numbers/{name}"] = np.stack([p["numbers"][i] for p in points])
        most = max([len(p["peaks"]) for p in points] + [1])
        peaks = np.full((len(points), most, 3), np.nan)
        for i, p in enumerate(points):
            peaks[i, :len(p["peaks"])] = p["peaks"]
        h5["points/peaks"] = peaks
        _describe(h5)
    os.replace(tmp, path)


def read(path):
    """Summary -> nested dict of arrays and attributes."""
    filekind.require(path, "summary", SummaryError)
    out = {}
    with filekind.reading(path, "the reduction summary", SummaryError):
        with h5py.File(path, "r") as h5:
            def visit(name, obj):
                if isinstance(obj, h5py.Dataset):
                    out[name] = obj[...]
            h5.visititems(visit)
            out["attrs"] = {k: h5.attrs[k] for k in h5.attrs}
        if out["attrs"].get("format") != FORMAT:
            raise SummaryError(f"{path}: summary format {out['attrs'].get('format', '(none)')}, this version "
                               f"reads {FORMAT}; reduce the catalog again")
        out["points/method"] = np.array([m.decode() for m in out["points/method"]])
    return out
