"""Rupture lengths: the number of blocks an event slips, n = 0..N, a size axis that means the same under
every friction law (the comparison's, analysis/compare.py; its module docstring defines the numbers).

Its table counts the inertial events per n on bins of the chain's own (0..N: each point has its N; a plane's
0..N M, Rows.n_blocks, n an area there), so that
every number is a function of summed counts. The numbers: the share of events with n >= n_large, the dip of
R(log10 n), the exponent tau of a discrete power law fitted to n_min <= n < n_large and the KS distance of
all n >= n_min from that law continued to N; the curve: R(log10 n) averaged over bins of LOG_BIN in log10 n.
"""
import math

import numpy as np

from . import Criterion, Curve, Number, Option, Statistic, Table

LOG_BIN = 0.2                                             # width of the bins of P(n) in log10 n
TAU_RANGE = (0.0, 10.0)


def chain_bins(n_blocks):
    """Bins of n = 0..N, one per integer (edges at the half integers)."""
    return np.arange(n_blocks + 2) - 0.5


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


def feed(acc, rows):
    if rows.ev is not None:
        acc.count("n_slipped", rows.block, rows.ev["n_slipped"], chain_bins(rows.n_blocks))


def estimate(u, opt):
    sizes = u["n_slipped"]
    edges = log_bins(len(sizes) - 1)
    tau = power_law_tau(sizes, opt.n_min, opt.n_large)
    return [sizes[opt.n_large:].sum() / max(sizes.sum(), 1), dip(size_density(sizes, edges), edges, opt.n_large),
            tau, power_law_ks(sizes, opt.n_min, tau)]


def density(u, opt, edges):
    """R(log10 n) on log_bins(N)."""
    sizes = u["n_slipped"]
    return size_density(sizes, log_bins(len(sizes) - 1))


STATISTIC = Statistic(
    "rupture", 70, sets=("compare",),
    tables=(Table("n_slipped", "count", "inertial events per number of blocks slipped n = 0..N, per task and stretch",
                  bins="n_slipped", chain_edges=chain_bins),),
    numbers=(Number("fraction_large_n", "1", "share of the events slipping n >= n_large blocks"),
             Number("dip", "1", "highest bin of R(log10 n) at n >= n_large over its lowest between n = 2 and it"),
             Number("tau", "1", "exponent of P(n) ~ n^-tau fitted to n_min <= n < n_large"),
             Number("ks_power_law", "1", "KS distance of the n >= n_min from that law continued to N")),
    curves=(Curve("size", "n_slipped", (), "log10 n", "all events", "1/log10 unit", values=density),),
    feed=feed, estimate=estimate,
    options=(Option("n_large", "count", 50, "blocks", "large event: at least this many blocks slip", 2, 10 ** 9),
             Option("n_min", "count", 1, "blocks", "smallest n of the power-law fit", 1, 10 ** 9)),
    criteria=(Criterion("n_slipped", "n_slipped", "n_large"),))
