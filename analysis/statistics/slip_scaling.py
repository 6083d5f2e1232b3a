"""The mean slip and the stress drop of an event against its rupture length (Kawamura et al., Phys. Rev. E 95,
042122, 2017: the mean slip and the mean stress drop tend to be independent of L_r for large events).

An event's mean slip is its total slip over the blocks it slipped, slip / L_r (L_r = /events/n_slipped); its
stress drop the mean drop of those blocks' forces by its slip (/events/stress_drop, ensemble/model/workspace.py:
D_STRESS_DROP; NaN in catalogs before bk-catalog-7, whose events are left out of the stress drop's sums alone).
The curves: the mean of each per bin of L_r (the lr bins of rupture_length.py). The numbers, over the events of
the L_0 fit's range lr_min <= L_r <= top = min(lr_max, N - 1) (N M - 1 on a plane, where L_r is an area:
rupture_length.py; "large" here): the mean of
each, and the ratio of its mean over the upper half of the range (L_r >= (lr_min + top) / 2) to its mean over
the lower half, 1 where it does not depend on L_r.
"""
import numpy as np

from . import Curve, Number, Statistic, Table
from .rupture_length import fit_range

NAME = "slip_scaling"
COLUMNS = ("n_lower", "slip_lower", "n_upper", "slip_upper")
DROP = "stress_drop"
DROP_COLUMNS = ("n_lower", "drop_lower", "n_upper", "drop_upper")


def feed(acc, rows):
    if rows.ev is None:
        return
    opt, length = rows.opt, rows.ev["n_slipped"]
    mean = rows.ev["slip"] / np.maximum(length, 1)
    drop = rows.ev["stress_drop"]
    known = ~np.isnan(drop)
    acc.count("slip_lr", rows.block, length, opt.lr_edges, weights=mean)
    acc.count("drop_n", rows.block[known], length[known], opt.lr_edges)
    acc.count("drop_lr", rows.block[known], length[known], opt.lr_edges, weights=drop[known])
    _, top = fit_range(opt.lr_min, opt.lr_max, rows.n_blocks)
    fit = (length >= opt.lr_min) & (length <= top)
    upper = fit & (2 * length >= opt.lr_min + top)
    lower = fit & ~upper
    for table, columns, values, among in ((NAME, COLUMNS, mean, fit), (DROP, DROP_COLUMNS, drop, known)):
        for count, total, mask in zip(columns[::2], columns[1::2], (lower & among, upper & among)):
            acc.add(table, count, rows.block[mask], 1)
            acc.add(table, total, rows.block[mask], values[mask])


def estimate(u, opt):
    return [*_mean_and_ratio(u, NAME, COLUMNS), *_mean_and_ratio(u, DROP, DROP_COLUMNS)]


def _mean_and_ratio(u, table, columns):
    n_lo, s_lo, n_hi, s_hi = (u.column(table, c) for c in columns)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [(s_lo + s_hi) / (n_lo + n_hi), (s_hi / n_hi) / (s_lo / n_lo)]


def mean_slip(u, opt, edges):
    """Mean slip per block of the events in each lr bin (NaN where none)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return u["slip_lr"] / u["lr"]


def mean_drop(u, opt, edges):
    """Mean stress drop of the events in each lr bin that have one (NaN where none)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return u["drop_lr"] / u["drop_n"]


STATISTIC = Statistic(
    NAME, 90,
    tables=(Table("slip_lr", "model length", "summed mean slip per block (slip / L_r) of the inertial events per "
                                             "rupture-length bin, per task and stretch", bins="lr", weights=True),
            Table(NAME, "count or sum", "events and their summed mean slip per block in the lower and upper half of "
                                        "the L_0 fit's range", columns=COLUMNS),
            Table("drop_n", "count", "inertial events with a stress drop (catalogs from bk-catalog-7) per "
                                     "rupture-length bin, per task and stretch", bins="lr"),
            Table("drop_lr", "model force", "summed stress drop of those events per rupture-length bin, per task "
                                            "and stretch", bins="lr", weights=True),
            Table(DROP, "count or sum", "events with a stress drop and their summed stress drop in the lower and "
                                        "upper half of the L_0 fit's range", columns=DROP_COLUMNS)),
    numbers=(Number("mean_slip_large", "model length", "mean slip per block (slip / L_r) of the events with "
                                                       "lr_min <= L_r <= min(lr_max, N - 1)", "mean slip (large)"),
             Number("slip_ratio", "1", "mean slip per block in the upper half of that range over the lower half's "
                                       "(1: independent of L_r)", "slip upper/lower"),
             Number("mean_drop_large", "model force", "mean stress drop of the events of that range (NaN: the "
                                                      "catalog keeps no stress drops)", "mean drop (large)"),
             Number("drop_ratio", "1", "mean stress drop in the upper half of that range over the lower half's "
                                       "(1: independent of L_r)", "drop upper/lower")),
    curves=(Curve("mean_slip", "slip_lr", (), "L_r", "the events of each rupture length", "model length",
                  values=mean_slip),
            Curve("mean_drop", "drop_lr", (), "L_r", "the events of each rupture length with a stress drop",
                  "model force", values=mean_drop)),
    feed=feed, estimate=estimate, uses_tables=("lr",), uses_options=("lr_bins", "lr_min", "lr_max"))
