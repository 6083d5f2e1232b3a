"""How periodic the large events by rupture length recur (the comparison's, analysis/compare.py): the local
recurrence times T of the events slipping n >= n_large blocks (rupture.py's criterion "n_slipped"; the next such event
with epicenter within `window` blocks), their coefficient of variation and the sharpness of their peak.

The sharpness scales T by its median, which is no function of sums: the recurrence times are a sample table
(statistics/__init__.py), the values themselves per unit, and a resample concatenates the drawn units' values
in the order drawn. Its numbers are then those of the resampled values exactly, the CV included (computed from
the values, std(ddof=1) / mean, not from sums of squares).
"""
import math

import numpy as np

from . import Number, Statistic, Table

SHARPNESS_BIN = 0.05                                      # bins of T / median(T) of the sharpness
POISSON_SHARPNESS = (1 - 2 ** -(SHARPNESS_BIN / 2)) / (SHARPNESS_BIN / 2)   # exponential T: 0.687


def recurrence_numbers(T):
    """(cv, sharpness) of recurrence times T (NaN with fewer than two; analysis/compare.py's docstring)."""
    if len(T) < 2 or np.median(T) <= 0:
        return math.nan, math.nan
    x = T / np.median(T)
    # bins centred on multiples of SHARPNESS_BIN, so that a peak at the median (x = 1) lies in
    # one bin; the first is [0, SHARPNESS_BIN / 2), half as wide
    counts = np.bincount((x / SHARPNESS_BIN + 0.5).astype(np.int64)).astype(float)
    counts[0] *= 2.0
    return float(T.std(ddof=1) / T.mean()), float(counts.max() / len(x) / SHARPNESS_BIN)


def feed(acc, rows):
    found = rows.scans.get("n_slipped")
    if found is not None:
        block, tnu, _ = found
        acc.append("T_n", block, tnu)


def estimate(u, opt):
    T = u["T_n"]
    return [len(T), *recurrence_numbers(T)]


STATISTIC = Statistic(
    "regularity", 71, needs=("recurrences:n_slipped",), sets=("compare",),
    tables=(Table("T_n", "model length", "T nu of the large events by rupture length (n >= n_large), per task and "
                                         "stretch of their starting event", sample=True),),
    numbers=(Number("n_recurrences_n", "count", "recurrences of the events with n >= n_large within `window` blocks"),
             Number("cv_n", "1", "their coefficient of variation std(T) / mean(T)"),
             Number("sharpness", "1", "the highest density of T / median(T) in bins of SHARPNESS_BIN")),
    feed=feed, estimate=estimate)
