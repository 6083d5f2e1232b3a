"""Estimators on histograms: densities, peaks, Gutenberg-Richter b-value, bootstrap.

Everything here works on additive per-unit quantities (histogram counts, sums),
so a statistic of any set of units is a function of their sum: that is what
makes merging across tasks and ranks exact and resampling cheap.
"""
import math

import numpy as np

LOG10_E = math.log10(math.e)

# columns of the per-unit statistics array
(N_EVENTS, N_LARGE, N_REC, SUM_TNU, N_REC_INT, SUM_TNU_INT, N_GR, SUM_MU_GR) = range(8)
N_STATS = 8


def density(counts, edges, total):
    """Probability density from bin counts; `total` counts the events in and out of range."""
    widths = np.diff(edges)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, counts / (np.maximum(total, 1) * widths), np.nan)


def centers(edges):
    return 0.5 * (edges[1:] + edges[:-1])


def find_peaks(counts, edges, rel_height=0.3, min_separation=4):
    """Positions of the local maxima of a [1, 4, 6, 4, 1]-smoothed histogram.

    A peak must reach rel_height of the highest one and lie at least
    min_separation bins from a higher peak. Returned in decreasing height; of equal
    heights the lower bin counts as the higher (a stable sort: numpy's default sort
    orders ties differently on different CPUs, so the peaks kept would too).
    """
    c = np.asarray(counts, dtype=float)
    if c.sum() <= 0:
        return np.zeros(0)
    s = np.convolve(np.pad(c, 2, mode="edge"), np.array([1, 4, 6, 4, 1]) / 16, mode="valid")
    is_max = np.r_[s[0] > s[1], (s[1:-1] >= s[:-2]) & (s[1:-1] > s[2:]), s[-1] > s[-2]]
    candidates = [i for i in np.argsort(-s, kind="stable") if is_max[i] and s[i] >= rel_height * s.max()]
    chosen = []
    for i in candidates:
        if all(abs(i - j) >= min_separation for j in chosen):
            chosen.append(i)
    return centers(edges)[chosen]


def b_value(n, sum_mu, cut):
    """Aki's maximum-likelihood Gutenberg-Richter b for magnitudes >= cut (continuous).

    b = log10(e) / (mean(mu) - cut); its standard error is b / sqrt(n).
    """
    if n < 2:
        return np.nan
    excess = sum_mu / n - cut
    return LOG10_E / excess if excess > 0 else np.nan


def gr_ks_distance(counts, edges, cut, b):
    """Largest gap between the binned CDF of mu >= cut and the fitted Gutenberg-Richter law."""
    if not np.isfinite(b):
        return np.nan
    keep = edges[:-1] >= cut - 1e-12
    c = np.asarray(counts, dtype=float)[keep]
    if c.sum() <= 0:
        return np.nan
    upper = edges[1:][keep]
    empirical = np.cumsum(c) / c.sum()
    model = 1.0 - 10.0 ** (-b * (upper - cut))
    return float(np.max(np.abs(empirical - model)))


def percentile_interval(samples, level):
    """Central interval of bootstrap samples along axis 0 (NaNs ignored)."""
    q = 50 * (1 - level)
    with np.errstate(all="ignore"):
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.nanpercentile(samples, q, axis=0), np.nanpercentile(samples, 100 - q, axis=0)


def bootstrap(units, statistic, n_resamples, rng):
    """Resample units with replacement; returns the statistic of each resample (stacked).

    units: array with one leading entry per unit (e.g. per seed); statistic:
    function of the sum over the chosen units.
    """
    m = len(units)
    picks = rng.integers(0, m, size=(n_resamples, m))
    return np.array([statistic(units[p].sum(axis=0)) for p in picks])
