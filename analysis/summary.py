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
"""
import os

import h5py
import numpy as np

from ensemble import filekind

from .reduce import NUMBERS, PARAMS

FORMAT = filekind.SUMMARY_FORMAT_PREFIX + "2"   # 2: GR b and its standard error, 9 per-task sums, peaks by prominence


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
