"""The mean slip of an event against its rupture length (Kawamura et al., Phys. Rev. E 95, 042122, 2017: the mean
slip, like the mean stress drop, tends to be independent of L_r for large events).

An event's mean slip is its total slip over the blocks it slipped, slip / L_r (L_r = /events/n_slipped). The
curve: the mean of that per bin of L_r (the lr bins of rupture_length.py). The numbers, over the events of the
L_0 fit's range lr_min <= L_r <= top = min(lr_max, N - 1) (rupture_length.py; "large" here): their mean slip
per block, and the ratio of the mean over the upper half of the range (L_r >= (lr_min + top) / 2) to the mean
over its lower half, 1 where the mean slip does not depend on L_r. (The stress drop needs a column the catalog
does not hold yet: issue 45.)
"""
import numpy as np

from . import Curve, Number, Statistic, Table
from .rupture_length import fit_range

NAME = "slip_scaling"
COLUMNS = ("n_lower", "slip_lower", "n_upper", "slip_upper")


def feed(acc, rows):
    if rows.ev is None:
        return
    opt, length = rows.opt, rows.ev["n_slipped"]
    mean = rows.ev["slip"] / np.maximum(length, 1)
    acc.count("slip_lr", rows.block, length, opt.lr_edges, weights=mean)
    _, top = fit_range(opt.lr_min, opt.lr_max, rows.n_blocks)
    fit = (length >= opt.lr_min) & (length <= top)
    upper = fit & (2 * length >= opt.lr_min + top)
    lower = fit & ~upper
    for count, total, mask in (("n_lower", "slip_lower", lower), ("n_upper", "slip_upper", upper)):
        acc.add(NAME, count, rows.block[mask], 1)
        acc.add(NAME, total, rows.block[mask], mean[mask])


def estimate(u, opt):
    n_lo, s_lo, n_hi, s_hi = (u.column(NAME, c) for c in COLUMNS)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [(s_lo + s_hi) / (n_lo + n_hi), (s_hi / n_hi) / (s_lo / n_lo)]


def mean_slip(u, opt, edges):
    """Mean slip per block of the events in each lr bin (NaN where none)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return u["slip_lr"] / u["lr"]


STATISTIC = Statistic(
    NAME, 90,
    tables=(Table("slip_lr", "model length", "summed mean slip per block (slip / L_r) of the inertial events per "
                                             "rupture-length bin, per task and stretch", bins="lr", weights=True),
            Table(NAME, "count or sum", "events and their summed mean slip per block in the lower and upper half of "
                                        "the L_0 fit's range", columns=COLUMNS)),
    numbers=(Number("mean_slip_large", "model length", "mean slip per block (slip / L_r) of the events with "
                                                       "lr_min <= L_r <= min(lr_max, N - 1)", "mean slip (large)"),
             Number("slip_ratio", "1", "mean slip per block in the upper half of that range over the lower half's "
                                       "(1: independent of L_r)", "slip upper/lower")),
    curves=(Curve("mean_slip", "slip_lr", (), "L_r", "the events of each rupture length", "model length",
                  values=mean_slip),),
    feed=feed, estimate=estimate, uses_tables=("lr",), uses_options=("lr_bins", "lr_min", "lr_max"))
