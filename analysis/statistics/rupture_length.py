"""The rupture-length distribution of the inertial events and its exponential tail, P(L_r) ~ exp(-L_r / L_0),
with the "seismic correlation length" L_0 (Kawamura et al., Phys. Rev. E 95, 042122, 2017).

L_r is the number of blocks an event slips (/events/n_slipped; on the chain a rupture is an interval, so it is
also last - first + 1). L_0 is the maximum-likelihood scale of the law restricted to the integers lr_min <= L_r
<= top, top = min(lr_max, N - 1): ruptures of the whole chain (L_r = N) are the chain's size, not the fault's,
and lie outside every fit. That law, P(L_r) = q^(L_r - lr_min) / sum_{k=0..K} q^k with q = exp(-1 / L_0) and
K = top - lr_min, has a mean excess E[L_r - lr_min] rising monotonically with L_0, from 0 to the flat law's K / 2;
L_0 is the root of that mean = the events' mean excess, which is a function of sums (events, excess, K), so a
resample's L_0 is that of its events exactly. No root (a mean excess at or above K / 2: the lengths do not fall
off over the range) gives NaN, as fewer than two events do. The definition of L_r and the range are this
code's choice: the paper's text was not at hand (docs/successors.md). lr_min's default, 200 blocks, lies past
the hump of P(L_r) at the seed paper's b = 20 (its peak near 130 blocks): from 50 the fit would take the hump's
rise for the tail. The tail is not quite exponential: L_0 falls as lr_min grows (docs/successors.md).

On a plane L_r is still the blocks an event slips, there an area (Rows.n_blocks = N M: the fit's top is
min(lr_max, N M - 1), ruptures of the whole plane out), and L_0 the scale of its tail in blocks, an area.
"""
import math

import numpy as np

from . import Curve, Figure, Number, Option, Statistic, Table

NAME = "rupture_length"
SCALE_RANGE = (1e-3, 1e9)     # L_0 in blocks: the bisection's bracket


def mean_excess(x, span):
    """E[k] for P(k) ~ exp(-x k), k = 0..span (x > 0)."""
    k = np.arange(span + 1, dtype=float)
    w = np.exp(-x * k)
    return float((k * w).sum() / w.sum())


def correlation_length(n, excess, span):
    """L_0 (blocks) of the exponential law on lr_min..lr_min + span fitted to n events of summed excess over
    lr_min `excess`; NaN for n < 2, span < 1 or no root (see the module's docstring)."""
    if not (n >= 2 and span >= 1):
        return math.nan
    span = int(round(span))
    m = excess / n
    if not 0.0 < m < span / 2.0:
        return math.nan
    lo, hi = (1.0 / SCALE_RANGE[1], 1.0 / SCALE_RANGE[0])   # x = 1 / L_0; the mean falls as x grows
    for _ in range(100):
        x = math.sqrt(lo * hi)
        if mean_excess(x, span) > m:
            lo = x
        else:
            hi = x
    return 1.0 / math.sqrt(lo * hi)


def fit_range(lr_min, lr_max, n_blocks):
    """(lr_min, top): the L_0 fit's range of a chain (or plane) of n_blocks, whole-chain (-plane) ruptures out."""
    return lr_min, min(lr_max, n_blocks - 1)


def feed(acc, rows):
    if rows.ev is None:
        return
    opt, length = rows.opt, rows.ev["n_slipped"]
    acc.count("lr", rows.block, length, opt.lr_edges)
    _, top = fit_range(opt.lr_min, opt.lr_max, rows.n_blocks)
    fit = (length >= opt.lr_min) & (length <= top)
    block = rows.block[fit]
    acc.add(NAME, "n_fit", block, 1)
    acc.add(NAME, "sum_excess", block, length[fit] - opt.lr_min)
    acc.add(NAME, "sum_span", block, top - opt.lr_min)


def estimate(u, opt):
    n, excess, span = (u.column(NAME, c) for c in ("n_fit", "sum_excess", "sum_span"))
    return [correlation_length(n, excess, span / n if n > 0 else 0), n]


def fitted_density(s, i, lengths):
    """The fitted law of point i of summary `s` as a density over all its inertial events, at integer `lengths`
    (NaN outside the fit's range and without an L_0)."""
    l0, n_fit = s["points/numbers/L0"][i, 0], s["points/numbers/n_L0"][i, 0]
    from ..summary import point_blocks
    lo, top = fit_range(int(s["attrs"]["lr_min"]), int(s["attrs"]["lr_max"]), int(point_blocks(s)[i]))
    out = np.full(len(lengths), np.nan)
    inside = (lengths >= lo) & (lengths <= top)
    if np.isfinite(l0) and n_fit > 0 and inside.any():
        q = math.exp(-1.0 / l0)
        norm = (1.0 - q ** (top - lo + 1)) / (1.0 - q)
        out[inside] = n_fit / s["points/numbers/n_events"][i, 0] * q ** (lengths[inside] - lo) / norm
    return out


def figure_size(n):
    from ..drawing import legend_columns
    return 8 + 1.6 * (legend_columns(n) - 1), 4.8


def draw(summaries, fig, keys, labels, names, title):
    """P(L_r) of every point overlaid on a log axis, with its band, and the fitted exp(-L_r / L_0) over the fit's
    range dashed in the same colour; L_0 with its interval in the legend."""
    from ..drawing import FONT, band, layout, legend_columns, palette
    from ..figure_labels import points_of
    from ..stats import centers
    from ..summary import point_blocks
    from . import number_text
    ax = fig.add_subplot()
    points = points_of(summaries)
    for (s, i), label, color in zip(points, labels, palette(len(points))):
        x = centers(s["bins/lr"])
        band(ax, x, s["points/lr_density"][i], s["points/lr_lo"][i], s["points/lr_hi"][i],
             f"{label}: $L_0$ = {number_text(*s['points/numbers/L0'][i], digits='.3g')}", color, log=True,
             open_ends=True)
        lengths = np.arange(int(point_blocks(s)[i]) + 1)
        ax.plot(lengths, fitted_density(s, i, lengths), "--", color=color, lw=1.0)
    ax.set_yscale("log")
    density = np.concatenate([s["points/lr_density"].ravel() for s in summaries])
    positive = density[density > 0]
    if positive.size:      # the data's range: the fitted law continued far below them is not the figure's
        ax.set_ylim(positive.min() / 3, positive.max() * 3)
    ax.set_xlabel(r"rupture length $L_r$ (blocks slipped)")
    ax.set_ylabel(r"$P(L_r)$ (per block)")
    ax.legend(title=r"varying " + ", ".join(keys) + r"; dashed: $\exp(-L_r/L_0)$ fitted", fontsize=FONT,
              title_fontsize=FONT + 1, loc="upper left", bbox_to_anchor=(1.01, 1.0),
              ncol=legend_columns(len(points)))
    layout(fig, title, 0.0)


STATISTIC = Statistic(
    NAME, 80,
    tables=(Table("lr", "count", "inertial events per rupture-length bin (blocks slipped), per task and stretch",
                  bins="lr"),
            Table(NAME, "count or sum", "the rupture lengths' exponential fit: events in its range, their summed "
                                        "excess over lr_min and summed range width",
                  columns=("n_fit", "sum_excess", "sum_span"))),
    numbers=(Number("L0", "blocks", "seismic correlation length: P(L_r) ~ exp(-L_r / L_0) fitted by maximum "
                                    "likelihood on lr_min <= L_r <= min(lr_max, N - 1)", "L_0"),
             Number("n_L0", "count", "events in the range of the L_0 fit", "L_0 fit events")),
    curves=(Curve("lr", "lr", ("numbers", "n_events"), "L_r", "all events", "1/block"),),
    feed=feed, estimate=estimate, uses_tables=("numbers",),
    options=(Option("lr_bins", "bins", "0.5:1600.5:320", "blocks", "rupture-length bins lo:hi:n of P(L_r)"),
             Option("lr_min", "count", 200, "blocks", "shortest rupture length of the L_0 fit", 1, 10 ** 9),
             Option("lr_max", "count", 10 ** 9, "blocks",
                    "longest rupture length of the L_0 fit (at most N - 1: whole-chain ruptures are out)",
                    1, 10 ** 9)),
    figures=(Figure("rupture_length", "P(L_r) of every point with its band and the fitted exp(-L_r / L_0)",
                    figure_size, draw),))
