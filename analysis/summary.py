"""The summary HDF5 written by `python -m analysis reduce`.

    /bins/mu, /bins/tnu                         bin edges
    /tasks/*                                    the task tables of the catalogs, one after the other
                                                (in the order given), one row per task, with
    /tasks/catalog, /tasks/catalog_task         its catalog (index into the attribute `catalogs`)
                                                and its index in that catalog
    /tasks/point                                the point it pools into (row of /points)
    /tasks/catalog_point                        its point in its catalog
    /tasks/seed_entropy, /tasks/spawn_key       its random stream (for a task that has not finished,
                                                the one the runner uses: analysis/merge.py)
    /per_task/{mu, tnu, tnu_interior}           (tasks, stretches, bins) counts
    /per_task/numbers                           (tasks, stretches, 8) counts and sums (analysis.stats)
    /points/{N, l, nu, a, b, c}                 parameters of each point (first appearance order)
    /points/method, /points/units               resampling used ("seeds" or "blocks") and unit count
    /points/{mu, tnu, tnu_interior}_density     (points, bins): estimate; *_lo, *_hi: interval
    /points/numbers/<name>                      (points, 3): estimate, lo, hi (see reduce.NUMBERS)
    /points/peaks                               (points, max peaks, 3): T*nu position, lo, hi (NaN pad)
    attributes: format; catalogs (the catalogs' paths, in the order given: /tasks/catalog indexes
                them) and configs (their stored configs, same order); config (the one catalog's
                config, only when there is one); catalog (the catalog's path, or for several a
                short description of them, for titles); partial ("" or the one-line statement of
                an unfinished reduction: events reduced of expected, which catalogs); mu_c, window,
                b_cut, bootstrap, level, blocks, seed (the options)

The tasks of a point are its resampling units in the order of their streams, (seed_entropy,
spawn_key); its bootstrap draws from SeedSequence(seed, spawn_key from its parameters)
(merge.bootstrap_rng), so its numbers do not depend on which catalogs held its tasks or in
which order they were given.

`format` tells a summary from a catalog (ensemble/filekind.py); summaries written before it
existed are known by their attributes and groups. Format 2 added catalogs, configs, partial and
the /tasks columns catalog, catalog_task and catalog_point.
"""
import os

import h5py
import numpy as np

from ensemble import filekind

from .reduce import NUMBERS, PARAMS

FORMAT = filekind.SUMMARY_FORMAT_PREFIX + "2"


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
    if os.path.exists(path) and not force:
        raise SummaryError(f"{path}: summary exists (use --force to overwrite it)")
    n_mu, n_tnu = len(opt.mu_edges) - 1, len(opt.tnu_edges) - 1
    tmp = str(path) + ".partial"
    with h5py.File(tmp, "w") as h5:
        h5.attrs.update({"format": FORMAT, **_source_attrs(inputs),
                         "mu_c": opt.mu_c, "window": opt.window, "b_cut": opt.b_cut,
                         "bootstrap": opt.bootstrap, "level": opt.level, "blocks": opt.blocks,
                         "seed": opt.seed})
        h5["bins/mu"] = opt.mu_edges
        h5["bins/tnu"] = opt.tnu_edges
        for name, values in inputs.tasks.items():
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
        out["points/method"] = np.array([m.decode() for m in out["points/method"]])
    return out
