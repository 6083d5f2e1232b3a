"""How regular the events come: the coefficient of variation of the local recurrence times (< 1
quasi-periodic, 1 Poisson, > 1 clustered), and the inter-event times of the whole fault (the time from
one inertial event's onset to the next's, whatever their size and place) with their mean and CV.

CV = std / mean with the sample standard deviation (n - 1), from additive sums of T and T^2, so that
resampled units give it exactly."""
import numpy as np

from . import Number, Statistic, Table


def feed(acc, rows):
    if rows.recurrences is not None:
        block, tnu, _ = rows.recurrences
        acc.add("intervals", "sum_tnu2", block, tnu ** 2)
    if rows.ev is None:
        return
    t = np.concatenate([[rows.t_before], rows.ev["t"]])
    gap = np.diff(t) * rows.nu
    first = 0 if np.isfinite(rows.t_before) else 1      # the task's first event closes no gap
    acc.add("intervals", "n_gaps", rows.block[first:], 1)
    acc.add("intervals", "sum_gap", rows.block[first:], gap[first:])
    acc.add("intervals", "sum_gap2", rows.block[first:], gap[first:] ** 2)


def cv(n, total, squares):
    """std (n - 1) / mean of values with count n, sum `total` and sum of squares `squares` (NaN for n < 2)."""
    if n < 2 or total <= 0:
        return np.nan
    mean = total / n
    return float(np.sqrt(max(squares - n * mean * mean, 0.0) / (n - 1)) / mean)


def estimate(u, opt):
    n, gaps = u.column("numbers", "n_rec"), u.column("intervals", "sum_gap")
    m = u.column("intervals", "n_gaps")
    with np.errstate(invalid="ignore", divide="ignore"):
        return [cv(n, u.column("numbers", "sum_tnu"), u.column("intervals", "sum_tnu2")), gaps / m,
                cv(m, gaps, u.column("intervals", "sum_gap2"))]


STATISTIC = Statistic(
    "intervals", 25, needs=("recurrences",),
    tables=(Table("intervals", "sum or count", "sums of the recurrence times' squares and of the whole fault's "
                                               "inter-event times",
                  columns=("sum_tnu2", "n_gaps", "sum_gap", "sum_gap2")),),
    numbers=(Number("cv_tnu", "1", "coefficient of variation of the local recurrence times T nu "
                                   "(< 1 quasi-periodic, 1 Poisson, > 1 clustered)", "CV of T*nu"),
             Number("mean_gap", "model length", "mean inter-event time of the whole fault, times nu "
                                                "(onset to the next inertial event's onset)", "mean gap*nu"),
             Number("cv_gap", "1", "coefficient of variation of the whole fault's inter-event times",
                    "CV of gaps")),
    feed=feed, estimate=estimate, uses_tables=("numbers",))
