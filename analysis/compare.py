"""Friction laws side by side, on a size axis that means the same under every law
(`python -m analysis compare`, docs/laws.md).

The magnitude mu = log10(total slip) has each law's own scale (the aging law's large events slip
~10^5, Carlson-Langer's ~10^2), so "more characteristic" is decided on the number of blocks an
event slips, n = 1..N, and on recurrence times divided by their mean:

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

Intervals come from the bootstrap of the reduction (reduce.py): over the seeds of a point when it
has at least MIN_UNITS, else over `blocks` stretches of each of its trajectories.
"""
import json
import math
import os
from dataclasses import dataclass

import numpy as np

from ensemble import checks, filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError

from . import merge, stats
from .recurrence import RecurrenceScanner
from .reduce import MIN_UNITS, PARAMS

NUMBERS = ("n_events", "fraction_large", "dip", "tau", "ks_power_law", "n_recurrences", "cv", "sharpness")
SHARPNESS_BIN = 0.05                                      # bins of T / median(T) of the sharpness
POISSON_SHARPNESS = (1 - 2 ** -(SHARPNESS_BIN / 2)) / (SHARPNESS_BIN / 2)   # exponential T: 0.687
LOG_BIN = 0.2                                             # width of the bins of P(n) in log10 n
MU_EDGES = np.linspace(-4.0, 7.0, 111)                    # magnitude bins of the R(mu) figure
TAU_RANGE = (0.0, 10.0)


@dataclass(frozen=True)
class Options:
    n_large: int = 50
    n_min: int = 1
    window: int = 10
    bootstrap: int = 1000
    level: float = 0.95
    blocks: int = 20
    seed: int = 0


# -- estimators (pure functions of the pooled counts and recurrence times) ---------------------

def power_law_tau(counts, n_min, n_max):
    """Maximum-likelihood exponent of P(n) ~ n^-tau on the integers n_min <= n < n_max, from the
    counts per n (counts[n]); the root of mean(ln n) under the law = the sample's (bisection:
    the model mean falls monotonically with tau). NaN without two distinct values, and where the root
    lies at an end of TAU_RANGE (no maximum inside it: sizes flat or rising over n_min..n_max)."""
    n = np.arange(n_min, n_max, dtype=float)
    c = np.asarray(counts[n_min:n_max], dtype=float)
    if c.sum() <= 0 or np.count_nonzero(c) < 2:
        return math.nan
    target = float((c * np.log(n)).sum() / c.sum())
    lo, hi = TAU_RANGE
    for _ in range(60):
        tau = 0.5 * (lo + hi)
        w = n ** -tau
        if (w * np.log(n)).sum() / w.sum() > target:
            lo = tau
        else:
            hi = tau
    tau = 0.5 * (lo + hi)
    return tau if TAU_RANGE[0] + 1e-9 < tau < TAU_RANGE[1] - 1e-9 else math.nan


def power_law_ks(counts, n_min, tau):
    """Largest gap between the CDF of the events with n >= n_min and P(n) ~ n^-tau on n_min..N."""
    c = np.asarray(counts[n_min:], dtype=float)
    if not np.isfinite(tau) or c.sum() <= 0:
        return math.nan
    model = np.arange(n_min, len(counts), dtype=float) ** -tau
    return float(np.max(np.abs(np.cumsum(c) / c.sum() - np.cumsum(model) / model.sum())))


def log_bins(n_blocks):
    """Bin edges in n (integers, first included) of width LOG_BIN in log10 n, each holding at
    least one integer; the last bin ends at N."""
    edges = [1]
    k = 1
    while edges[-1] <= n_blocks:
        edge = max(math.ceil(10 ** (k * LOG_BIN) - 1e-9), edges[-1] + 1)
        if edge > edges[-1]:
            edges.append(edge)
        k += 1
    edges[-1] = n_blocks + 1     # no bin reaches past the chain
    return np.array(edges)


def size_density(counts, edges):
    """R(log10 n) averaged over each bin: events in the bin / all events / the bin's width in
    log10 n, each integer n taking 1 / (n ln 10) of it (so that a power law P(n) ~ n^-tau
    becomes R ~ n^(1 - tau), as R(mu) of the Gutenberg-Richter law)."""
    total = counts.sum()
    sums = np.add.reduceat(np.asarray(counts, dtype=float), edges[:-1])[:len(edges) - 1]
    share = 1.0 / (np.arange(1, edges[-1], dtype=float) * math.log(10.0))
    widths = np.add.reduceat(share, edges[:-1] - 1)[:len(edges) - 1]
    return sums / max(total, 1) / widths


def dip(density, edges, n_large):
    """Highest P(n) bin at n >= n_large over the lowest between n = 2 and that peak."""
    large = np.flatnonzero(edges[:-1] >= n_large)
    if len(large) == 0 or not np.any(density[large] > 0):
        return math.nan
    peak = large[np.argmax(density[large])]
    below = np.flatnonzero((edges[:-1] >= 2) & (np.arange(len(density)) <= peak))
    low = density[below].min()
    return float(density[peak] / low) if low > 0 else math.inf


def recurrence_numbers(T):
    """(cv, sharpness) of recurrence times T (NaN with fewer than two; module docstring)."""
    if len(T) < 2 or np.median(T) <= 0:
        return math.nan, math.nan
    x = T / np.median(T)
    # bins centred on multiples of SHARPNESS_BIN, so that a peak at the median (x = 1) lies in
    # one bin; the first is [0, SHARPNESS_BIN / 2), half as wide
    counts = np.bincount((x / SHARPNESS_BIN + 0.5).astype(np.int64)).astype(float)
    counts[0] *= 2.0
    return float(T.std(ddof=1) / T.mean()), float(counts.max() / len(x) / SHARPNESS_BIN)


# -- streaming a point's tasks into resampling units -------------------------------------------

@dataclass
class Units:
    """A point's resampling units: counts per n (units, N + 1), counts per mu bin, recurrence
    times divided by nothing yet (one array per unit, in model time times nu)."""
    sizes: np.ndarray
    mu: np.ndarray
    T: list


def task_units(path, task, opt):
    """Stretches of one task's inertial events (/events/kind 0; its creep episodes are no events here):
    (sizes, mu, [T per stretch])."""
    with filekind.reading(path, "the event catalog", CatalogError), reader.Reader(path) as cat:
        written = cat.count(task, schema.KIND_EVENT)
        n_blocks, nu = int(cat.tasks["N"][task]), float(cat.tasks["nu"][task])
        k = opt.blocks
        sizes = np.zeros((k, n_blocks + 1), np.int64)
        mu_counts = np.zeros((k, len(MU_EDGES) - 1), np.int64)
        T = [[] for _ in range(k)]
        scanner = RecurrenceScanner(n_blocks, 0.5, opt.window)
        lo = 0
        for ev in cat.task_events(task, kind=schema.KIND_EVENT):
            hi = lo + len(ev["t"])
            block = (np.arange(lo, hi) * k) // max(written, 1)
            n = ev["n_slipped"].astype(np.int64)
            np.add.at(sizes, (block, n), 1)
            idx = np.searchsorted(MU_EDGES, ev["mu"], side="right") - 1
            ok = (idx >= 0) & (idx < len(MU_EDGES) - 1)
            np.add.at(mu_counts, (block[ok], idx[ok]), 1)
            # the scanner's "magnitude" is 1 for a large event, 0 otherwise (threshold 0.5)
            src, t_rec, _ = scanner.feed(ev["t"], ev["epicenter"], (n >= opt.n_large).astype(float),
                                         ev["boundary"])
            for b, value in zip((src * k) // max(written, 1), t_rec * nu):
                T[b].append(value)
            lo = hi
    return sizes, mu_counts, [np.array(t) for t in T]


def point_units(paths, tasks, rows, opt):
    parts = [task_units(paths[tasks["catalog"][g]], int(tasks["catalog_task"][g]), opt) for g in rows]
    if len(parts) >= MIN_UNITS:      # seeds
        return Units(np.stack([p[0].sum(axis=0) for p in parts]), np.stack([p[1].sum(axis=0) for p in parts]),
                     [np.concatenate(p[2]) for p in parts]), "seeds"
    return Units(np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                 [t for p in parts for t in p[2]]), "blocks"


def statistics(sizes, mu, T, opt, edges):
    """(numbers in NUMBERS order, P(n) per bin, R(mu)) of pooled counts and recurrence times."""
    total = sizes.sum()
    density = size_density(sizes, edges)
    tau = power_law_tau(sizes, opt.n_min, opt.n_large)
    cv, sharp = recurrence_numbers(T)
    numbers = np.array([total, sizes[opt.n_large:].sum() / max(total, 1), dip(density, edges, opt.n_large), tau,
                        power_law_ks(sizes, opt.n_min, tau), len(T), cv, sharp])
    return numbers, density, stats.density(mu, MU_EDGES, total)


def compare_point(paths, tasks, params, rows, opt):
    units, method = point_units(paths, tasks, rows, opt)
    n_blocks = units.sizes.shape[1] - 1
    edges = log_bins(n_blocks)
    sizes = units.sizes.sum(axis=0)
    est = statistics(sizes, units.mu.sum(axis=0), np.concatenate(units.T), opt, edges)
    rng = merge.bootstrap_rng(opt.seed, params)
    m = len(units.T)
    draws = [statistics(units.sizes[p].sum(axis=0), units.mu[p].sum(axis=0),
                        np.concatenate([units.T[i] for i in p]), opt, edges)
             for p in rng.integers(0, m, size=(opt.bootstrap, m))]
    intervals = [stats.percentile_interval(np.array([d[j] for d in draws]), opt.level) for j in range(3)]
    return {"numbers": est[0], "numbers_lo": intervals[0][0], "numbers_hi": intervals[0][1],
            "size_edges": edges, "size_density": est[1], "size_lo": intervals[1][0], "size_hi": intervals[1][1],
            "mu_density": est[2], "mu_lo": intervals[2][0], "mu_hi": intervals[2][1],
            "T": np.concatenate(units.T), "method": method, "units": m,
            "fit_share": sizes[opt.n_min:opt.n_large].sum() / max(sizes.sum(), 1)}


def label(law, params):
    keys = [k for k in PARAMS[3:] if params[k] == params[k]]   # (the law's keys: others are NaN)
    return f"{law}: " + ", ".join(f"{k} = {params[k]:g}" for k in keys)


def _check_memory(opt, n_tasks, n_blocks):
    """Refuse options whose arrays this machine cannot hold (checks.memory): a point's stretches
    of counts per n and per mu bin, and each resample's picks and numbers."""
    units = n_tasks * opt.blocks
    n_bytes = 8 * units * (n_blocks + 1 + len(MU_EDGES)) + 8 * opt.bootstrap * (units + len(MU_EDGES) + 2 * n_blocks)
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
        _check_memory(opt, len(rows), int(params["N"]))
    out = []
    for params, rows in inputs.points:
        law = params["law"]
        n_blocks = int(params["N"])
        if opt.n_large > n_blocks:
            raise ValueError(f"--n-large {opt.n_large} exceeds the chain of {n_blocks} blocks")
        result = compare_point(inputs.paths, inputs.tasks, params, rows, opt)
        result.update(law=law, params=params, label=label(law, params))
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
    with open(os.path.join(out_dir, "comparison.md"), "w") as f:
        f.write(table(points, opt, command))
    numbers = [{"label": p["label"], "law": p["law"], "method": p["method"], "units": p["units"],
                **{name: [float(p["numbers"][j]), float(p["numbers_lo"][j]), float(p["numbers_hi"][j])]
                   for j, name in enumerate(NUMBERS)}} for p in points]
    with open(os.path.join(out_dir, "comparison.json"), "w") as f:
        json.dump({"options": opt.__dict__, "points": numbers}, f, indent=1)
    figures(points, opt, out_dir, MU_EDGES)
    return [os.path.join(out_dir, n) for n in OUTPUTS]
