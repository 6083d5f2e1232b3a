"""Estimators on histograms: densities, peaks, the Gutenberg-Richter exponent, bootstrap.

Everything here works on additive per-unit quantities (histogram counts, sums),
so a statistic of any set of units is a function of their sum: that is what
makes merging across tasks and ranks exact and resampling cheap.
"""
import math

import numba as nb
import numpy as np

import ensemble.model  # noqa: F401  (first: numba caches the kernels in the package's cache, ensemble/kernel_cache.py)

LOG10_E = math.log10(math.e)


def density(counts, edges, total, widths=None):
    """Probability density from bin counts; `total` counts the events in and out of range (widths: the
    bins' widths, np.diff(edges), when the caller has them)."""
    widths = np.diff(edges) if widths is None else widths
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, counts / (np.maximum(total, 1) * widths), np.nan)


def centers(edges):
    return 0.5 * (edges[1:] + edges[:-1])


SMOOTHING = np.array([1, 4, 6, 4, 1]) / 16   # the histogram is smoothed with these weights (edges padded)
PEAK_Z = 3.0    # a peak's prominence must exceed this many noise standard deviations


def _edge_padded(counts):
    """The counts as floats with the edge bins repeated twice beyond each edge."""
    c = np.asarray(counts, dtype=float)
    return np.concatenate([c[:1], c[:1], c, c[-1:], c[-1:]])


def smooth(counts):
    """The [1, 4, 6, 4, 1] / 16 smoothed histogram (the edge bins repeated beyond the edges)."""
    return np.convolve(_edge_padded(counts), SMOOTHING, mode="valid")


def poisson_noise(counts):
    """Standard deviation of each smoothed bin if the counts were independent Poisson variables."""
    return np.sqrt(np.convolve(_edge_padded(counts), SMOOTHING ** 2, mode="valid"))


@nb.njit(cache=True)
def prominence(s, i):
    """(prominence, base bin) of the local maximum i of s, as scipy.signal.peak_prominences defines it:
    on each side the lowest value before a higher one (or the end); the higher of the two is the base."""
    base, level = -1, -np.inf
    for step in (-1, 1):
        j, low, where = i + step, np.inf, -1
        while 0 <= j < len(s) and s[j] <= s[i]:
            if s[j] < low:
                low, where = s[j], j
            j += step
        if where >= 0 and low > level:
            level, base = low, where
    return (s[i] - level, base) if base >= 0 else (s[i], i)


@nb.njit(cache=True)
def local_maxima(s):
    """(bins, prominences, base bins) of the local maxima of s (the right end of a plateau) inside its ends."""
    bins, heights, bases = [], [], []
    for i in range(1, len(s) - 1):
        if s[i] >= s[i - 1] and s[i] > s[i + 1]:
            height, base = prominence(s, i)
            bins.append(i)
            heights.append(height)
            bases.append(base)
    return np.array(bins, dtype=np.int64), np.array(heights, dtype=np.float64), np.array(bases, dtype=np.int64)


def find_peaks(counts, edges, noise, z=PEAK_Z):
    """Positions (bin centres) of the significant peaks of a histogram, highest first.

    The histogram is smoothed (`smooth`) and padded with an empty bin on each side, so that a
    maximum at an edge is a peak and the highest bin always has a base. A local maximum
    (the right end of a plateau) is a peak when its prominence (`prominence`) exceeds
    z * sqrt(noise[peak]^2 + noise[base]^2), `noise` being the standard deviation of each
    smoothed bin (reduce.py: from the bootstrap over resampling units, at least the Poisson
    value). On equal heights the lower bin comes first.
    """
    s = np.concatenate([[0.0], smooth(counts), [0.0]])
    sd = np.concatenate([[0.0], np.asarray(noise, dtype=float), [0.0]])
    found = [int(i) for i, height, base in zip(*local_maxima(s)) if height > z * math.hypot(sd[i], sd[base])]
    found.sort(key=lambda i: (-s[i], i))
    return centers(edges)[np.array(found, dtype=np.int64) - 1]


def gr_b(n, sum_mu, cut):
    """Aki's maximum-likelihood Gutenberg-Richter exponent ("GR b", not the model's b) of the
    n magnitudes >= cut (continuous, no binning correction): log10(e) / (mean(mu) - cut)."""
    if n < 2:
        return np.nan
    excess = sum_mu / n - cut
    return LOG10_E / excess if excess > 0 else np.nan


def gr_b_standard_error(n, sum_mu, sum_mu2, cut):
    """Shi & Bolt (1982) standard error of GR b: ln(10) b^2 sqrt(sum (mu - mean)^2 / (n (n - 1))).

    For independent magnitudes it is close to Aki's b / sqrt(n); it assumes independent events,
    so the bootstrap interval over seeds or stretches is the one to trust for a correlated catalog.
    """
    b = gr_b(n, sum_mu, cut)
    if not np.isfinite(b):
        return np.nan
    mean = sum_mu / n
    squares = max(sum_mu2 - n * mean * mean, 0.0)
    return math.log(10.0) * b * b * math.sqrt(squares / (n * (n - 1)))


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
