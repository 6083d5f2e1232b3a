"""Friction laws side by side, on a size axis that means the same under every law
(`python -m analysis compare`, docs/laws.md).

The magnitude mu = log10(total slip) has each law's own scale (the aging law's large events slip
~10^5, Carlson-Langer's ~10^2), so "more characteristic" is decided on the number of blocks an
event slips, n = 1..N (N M on a plane: an area), and on recurrence times divided by their mean:

- fraction_large: share of events with n >= n_large (default 50, N / 16 at N = 800: about the 1st
  percentile of the rupture length of the aging law's mu >= 4 events at b = 20).
- dip: R(log10 n), the density of log10 n (as R(mu) is the density of mu: P(n) n ln 10), averaged
  over bins of 0.2 in log10 n; its highest bin at n >= n_large over its lowest bin between n = 2
  and that peak (1 where it falls all the way to the peak: no dip).
- tau, ks_power_law: a discrete power law P(n) ~ n^-tau fitted by maximum likelihood to the small
  events, n_min <= n < n_large (the Gutenberg-Richter law of the rupture length), and the largest
  gap between the empirical CDF of every event with n >= n_min and that law continued to n = N
  (0 for a chain that follows its small events' power law all the way).
- cv, sharpness: local recurrence times T of large events (the next large event with epicenter
  within `window` blocks, as analysis/recurrence.py scans them): the coefficient of variation
  std(T) / mean(T) (1 for a Poisson process, 0 for a periodic one), and the height of the highest
  bin of the density of x = T / median(T) in bins of SHARPNESS_BIN (the median, not the mean:
  the long tails of T would move the mean), bins centred on multiples of SHARPNESS_BIN. A Poisson
  process gives POISSON_SHARPNESS (its density ln 2 exp(-x ln 2) averaged over the first, half
  bin [0, SHARPNESS_BIN / 2)), a periodic one 1 / SHARPNESS_BIN.

The comparison is a set of statistics of the one reduction (analysis/reduce.py, the engine): the magnitude
distribution (statistics/magnitude.py: R(mu) on --mu-bins, by default one axis spanning the
laws' scales), the rupture lengths
(statistics/rupture.py: counts per n on the chain's own bins 0..N, the size numbers and R(log10 n)) and the
regularity (statistics/regularity.py: the recurrence times of the events with n >= n_large, a sample table,
whose median and CV a resample computes from its values exactly). This module chooses the set, reads its
numbers and curves, and writes the table, the json and the figures (compare_plot.py).

Intervals come from the engine's bootstrap: over the seeds of a point when it has at least MIN_UNITS, else
over `blocks` stretches of each of its trajectories, drawn from merge.bootstrap_rng(seed, the point's
parameters). A point of one unit has no interval (the engine's rule).
"""
import json
import math
import os

import numpy as np

from ensemble import checks, space

from . import merge
from .reduce import PARAMS, point_statistics
from .statistics import Layout, of
# F401: the comparison's estimators, reached as compare.<name> too (tests/test_compare.py)
from .statistics.regularity import POISSON_SHARPNESS, SHARPNESS_BIN, recurrence_numbers  # noqa: F401
from .statistics.rupture import (LOG_BIN, TAU_RANGE, dip, log_bins, power_law_ks, power_law_tau,  # noqa: F401
                                 size_density)

NUMBERS = ("n_events", "fraction_large", "dip", "tau", "ks_power_law", "n_recurrences", "cv", "sharpness")
# each of the comparison's numbers (NUMBERS, its json's names) by its statistic's name in the engine
ENGINE_NUMBERS = ("n_events", "fraction_large_n", "dip", "tau", "ks_power_law", "n_recurrences_n", "cv_n",
                  "sharpness")
LAYOUT = Layout(of("compare"))                            # the comparison's statistics


def compare_point(per_task, params, rows, opt):
    """A point's numbers (NUMBERS order, with lo and hi), R(log10 n), R(mu), recurrence times, from the engine."""
    n_blocks = _blocks(params)
    result = point_statistics(per_task, rows, opt, merge.bootstrap_rng(opt.seed, params),
                              LAYOUT, n_blocks, geometry_name=params.get("geometry", "chain"))
    names = [n.name for n in LAYOUT.numbers]
    x = result["numbers"][[names.index(name) for name in ENGINE_NUMBERS]]
    sizes, size, mu = result["sums"]["n_slipped"], result["curve"]["size"], result["curve"]["mu"]
    return {"numbers": x[:, 0], "numbers_lo": x[:, 1], "numbers_hi": x[:, 2],
            "size_edges": log_bins(n_blocks), "size_density": size[0], "size_lo": size[1], "size_hi": size[2],
            "mu_density": mu[0], "mu_lo": mu[1], "mu_hi": mu[2],
            "T": result["sums"]["T_n"], "method": result["method"], "units": result["units"],
            "fit_share": sizes[opt.n_min:opt.n_large].sum() / max(sizes.sum(), 1), "n_blocks": n_blocks}


def _blocks(params):
    """A point's number of blocks: N, or N M on a plane (the sizes n reach it)."""
    return int(params["N"]) * int(params.get("M", 1))


def label(law, params):
    keys = [k for k in PARAMS[3:] if params[k] == params[k]]   # (the law's keys: others are NaN)
    shape = (f"{params['geometry']} {int(params['N'])} x {int(params['M'])}, l_across = {params['l_across']:g}: "
             if "geometry" in params else "")
    return f"{law}: " + shape + ", ".join(f"{k} = {params[k]:g}" for k in keys)


def _check_memory(opt, n_tasks, n_blocks):
    """Refuse options whose arrays this machine cannot hold (checks.memory): the stretches of counts per n
    and per mu bin of every task, and each resample's picks and numbers."""
    units = n_tasks * opt.blocks
    n_mu = len(opt.mu_edges)
    n_bytes = 8 * units * (n_blocks + 1 + n_mu) + 8 * opt.bootstrap * (units + n_mu + 2 * n_blocks)
    checks.memory(f"--blocks {opt.blocks} and --bootstrap {opt.bootstrap} over {n_tasks} tasks of {n_blocks} blocks",
                  n_bytes)


def compare(paths, opt):
    """Every point of the catalogs compared: a list of dicts (compare_point's, with law, params, label)."""
    if opt.n_large < 2 or opt.n_min < 1 or opt.n_min >= opt.n_large - 1:
        raise checks.UsageError("--n-min must be >= 1 and --n-large at least n-min + 2")
    if not (0 < opt.level < 1) or opt.bootstrap < 1 or opt.blocks < 1 or opt.window < 0:
        raise checks.UsageError("--level must be in (0, 1); --bootstrap, --blocks >= 1; --window >= 0")
    inputs = merge.read(paths)
    for params, rows in inputs.points:
        _check_memory(opt, len(rows), _blocks(params))
        if opt.n_large > _blocks(params):
            raise ValueError(f"--n-large {opt.n_large} exceeds the {params.get('geometry', 'chain')} of "
                             f"{_blocks(params)} blocks")
    out = []
    for params, rows in inputs.points:   # a point's tasks reduced together, then dropped
        per_task = merge.reduce_share(inputs, rows, opt, LAYOUT)
        result = compare_point(per_task, params, rows, opt)
        result.update(law=params["law"], params=params, label=label(params["law"], params))
        out.append(result)
    return out


# -- output --------------------------------------------------------------------------------------

def _cell(est, lo, hi):
    def g(x):
        return "inf" if x == math.inf else "n/a" if math.isnan(x) else f"{x:.3g}"
    return f"{g(est)} [{g(lo)}, {g(hi)}]" if np.isfinite(est) and np.isfinite(lo) else g(est)


def table(points, opt, command):
    head = ["point", "events", "large (n >= %d)" % opt.n_large, "dip", "tau", "KS to power law",
            "recurrences", "CV", "sharpness"]
    lines = [f"<!-- written by `{command}` -->",
             f"Intervals: {int(100 * opt.level)}% bootstrap ({opt.bootstrap} resamples). Poisson recurrence: "
             f"CV 1, sharpness {POISSON_SHARPNESS:.3f} (peak density of T / median(T)).", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for p in points:
        x, lo, hi = p["numbers"], p["numbers_lo"], p["numbers_hi"]
        cells = [p["label"], f"{int(x[0])}"]
        for j in (1, 2, 3, 4):
            cells.append(_cell(x[j], lo[j], hi[j]))
        cells.append(f"{int(x[5])}")
        for j in (6, 7):
            cells.append(_cell(x[j], lo[j], hi[j]))
        lines.append("| " + " | ".join(cells) + " |")
    if any(not np.all(np.isfinite(p["numbers"][[2, 3, 4, 6, 7]])) for p in points):
        lines += ["", f"inf: R(log10 n) is empty in a bin between n = 2 and its peak at n >= {opt.n_large}; n/a: no "
                      f"power law fits the sizes below n = {opt.n_large} (fewer than two, or not falling), or fewer "
                      "than two recurrences."]
    return "\n".join(lines) + "\n"


OUTPUTS = ("comparison.md", "comparison.json", "size.png", "magnitude.png", "recurrence.png")


def check_output(out_dir, force, inputs=()):
    """Refuse (checks.UsageError) a comparison directory that cannot be made or written, that is
    one of the inputs, or that holds a comparison without force (before the work, and when writing)."""
    checks.output(out_dir, inputs=inputs, force=force, directory=True, what="comparison directory")
    if os.path.isdir(out_dir):
        for name in OUTPUTS:
            checks.output(os.path.join(out_dir, name), inputs=inputs, force=force, what="comparison file")


def write(points, opt, out_dir, command, force=False, inputs=()):
    """comparison.md, comparison.json, size.png, magnitude.png, recurrence.png in out_dir."""
    from .compare_plot import figures
    check_output(out_dir, force, inputs)
    os.makedirs(out_dir, exist_ok=True)
    space.write_file(os.path.join(out_dir, "comparison.md"), table(points, opt, command), "the comparison table")
    numbers = [{"label": p["label"], "law": p["law"], "method": p["method"], "units": p["units"],
                **{name: [float(p["numbers"][j]), float(p["numbers_lo"][j]), float(p["numbers_hi"][j])]
                   for j, name in enumerate(NUMBERS)}} for p in points]
    space.write_file(os.path.join(out_dir, "comparison.json"),
                     json.dumps({"options": {k: np.asarray(v).tolist() for k, v in opt.values().items()},
                                 "points": numbers}, indent=1), "the comparison numbers")
    figures(points, opt, out_dir, opt.mu_edges)
    return [os.path.join(out_dir, n) for n in OUTPUTS]
