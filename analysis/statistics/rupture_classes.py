"""Unilateral and bilateral ruptures (Kawamura et al., Phys. Rev. E 95, 042122, 2017: one class of events tends
to be unilateral with its epicenter at the rim of the rupture zone of the preceding event, the other bilateral,
"asperity"-like): the share of each, where their epicenters lie against the previous large event's rupture zone,
and R(mu) of each class.

The classes, as this code defines them (the paper's text was not at hand; docs/successors.md):
- classified: an inertial event that slips at least class_min blocks and reaches neither end of the chain (a
  rupture stopped by an end is one-sided by the chain, not by its own dynamics);
- unilateral: its epicenter lies within uni_edge of its rupture zone's length [first, last] from one end of it,
  min(e - first, last - e) <= uni_edge (last - first); bilateral: every other classified event;
- at the rim: its epicenter within `window` blocks (the recurrences' window) of an end of the rupture zone of the
  task's last large event (mu >= mu_c) before it, min(|e - first'|, |e - last'|) <= window; counted among the
  events of each class that have such a predecessor.

A chain's statistic: on a plane the rupture zone is an area, not an interval, and the catalog keeps only its
extents, not its rim; a plane's points have no numbers here (statistics.refusal).
"""
import numpy as np

from . import Curve, Figure, Number, Option, Statistic, Table

NAME = "rupture_classes"
COLUMNS = ("n_classified", "n_uni", "n_bi", "n_uni_prev", "n_uni_rim", "n_bi_prev", "n_bi_rim")


def classes(ev, opt, n_blocks, previous):
    """(classified, unilateral, has_previous, at_rim) masks of the events `ev` (columns of one chunk, in order),
    `previous` the (first, last) of the task's last large event before them ((-1, -1): none); and the (first,
    last) of the last large event of the chunk or before."""
    first, last, epicenter = (np.asarray(ev[c], dtype=np.int64) for c in ("first", "last", "epicenter"))
    n = len(first)
    large = ev["mu"] >= opt.mu_c
    before = np.maximum.accumulate(np.concatenate([[-1], np.where(large, np.arange(n), -1)[:-1]]))
    prev_first = np.where(before >= 0, first[np.maximum(before, 0)], previous[0])
    prev_last = np.where(before >= 0, last[np.maximum(before, 0)], previous[1])
    has_previous = prev_first >= 0
    at_rim = has_previous & (np.minimum(np.abs(epicenter - prev_first), np.abs(epicenter - prev_last)) <= opt.window)
    classified = (ev["n_slipped"] >= opt.class_min) & (first > 0) & (last < n_blocks - 1)
    unilateral = classified & (np.minimum(epicenter - first, last - epicenter) <= opt.uni_edge * (last - first))
    if large.any():
        k = np.flatnonzero(large)[-1]
        previous = (int(first[k]), int(last[k]))
    return classified, unilateral, has_previous, at_rim, previous


def feed(acc, rows):
    if rows.ev is None:
        return
    carry = acc.carry.setdefault(NAME, {"previous": (-1, -1)})
    classified, uni, has_previous, at_rim, carry["previous"] = classes(rows.ev, rows.opt, rows.n_blocks,
                                                                       carry["previous"])
    bi = classified & ~uni
    block, mu = rows.block, rows.ev["mu"]
    for column, mask in zip(COLUMNS, (classified, uni, bi, uni & has_previous, uni & at_rim, bi & has_previous,
                                      bi & at_rim)):
        acc.add(NAME, column, block[mask], 1)
    acc.count("mu_uni", block[uni], mu[uni], rows.opt.mu_edges)
    acc.count("mu_bi", block[bi], mu[bi], rows.opt.mu_edges)


def estimate(u, opt):
    n, uni, _, uni_prev, uni_rim, bi_prev, bi_rim = (u.column(NAME, c) for c in COLUMNS)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [n, uni / n, uni_rim / uni_prev, bi_rim / bi_prev]


def figure_size(n):
    from ..drawing import grid
    rows, cols = grid(n)
    return 5.5 * cols, 4 * rows + 0.4


def draw(summaries, fig, keys, labels, names, title):
    """One panel per point: R(mu) of its unilateral and of its bilateral events, each with its band, and the shares
    in the panel's title."""
    from ..drawing import FONT, band, grid, layout
    from ..figure_labels import points_of
    from ..stats import centers
    from . import number_text
    points = points_of(summaries)
    rows, cols = grid(len(points))
    for k, ((s, i), label) in enumerate(zip(points, labels)):
        ax = fig.add_subplot(rows, cols, k + 1)
        x = centers(s["bins/mu"])
        for curve, whose, color in (("mu_uni", "unilateral", "C0"), ("mu_bi", "bilateral", "C3")):
            band(ax, x, s[f"points/{curve}_density"][i], s[f"points/{curve}_lo"][i], s[f"points/{curve}_hi"][i],
                 whose, color, log=True, open_ends=True)
        ax.set_yscale("log")
        ax.set_xlabel(r"magnitude $\mu$")
        ax.set_ylabel(r"$R(\mu)$ of the class")
        ax.set_title(f"{label}\nunilateral {number_text(*s['points/numbers/fraction_unilateral'][i], digits='.2f')}"
                     f"; at the rim: uni {number_text(*s['points/numbers/uni_at_rim'][i], digits='.2f')}, "
                     f"bi {number_text(*s['points/numbers/bi_at_rim'][i], digits='.2f')}", fontsize=FONT)
        ax.legend(fontsize=FONT)
    layout(fig, title, 0.0)


STATISTIC = Statistic(
    NAME, 85,
    tables=(Table(NAME, "count", "classified, unilateral and bilateral events, those with a previous large event "
                                 "and those at its rim", columns=COLUMNS),
            Table("mu_uni", "count", "unilateral events per magnitude bin, per task and stretch", bins="mu"),
            Table("mu_bi", "count", "bilateral events per magnitude bin, per task and stretch", bins="mu")),
    numbers=(Number("n_classified", "count", "events classified unilateral or bilateral (at least class_min blocks "
                                             "slipped, neither chain end reached)", "classified"),
             Number("fraction_unilateral", "1", "share of the classified events that are unilateral (epicenter "
                                                "within uni_edge of the zone's length from one of its ends)",
                    "unilateral"),
             Number("uni_at_rim", "1", "share of the unilateral events after a large one whose epicenter lies "
                                       "within `window` blocks of an end of its rupture zone", "uni at rim"),
             Number("bi_at_rim", "1", "the same share of the bilateral events", "bi at rim")),
    curves=(Curve("mu_uni", "mu_uni", (NAME, "n_uni"), "mu", "unilateral events", "1/mu"),
            Curve("mu_bi", "mu_bi", (NAME, "n_bi"), "mu", "bilateral events", "1/mu")),
    feed=feed, estimate=estimate, uses_options=("mu_bins", "mu_c", "window"),
    options=(Option("class_min", "count", 10, "blocks", "shortest rupture classified unilateral or bilateral",
                    1, 10 ** 9),
             Option("uni_edge", "number", 0.1, "1", "unilateral: epicenter within this share of the rupture "
                                                    "zone's length from one of its ends", 0.0, 0.5)),
    figures=(Figure("rupture_classes", "R(mu) of the unilateral and of the bilateral events of every point",
                    figure_size, draw),),
    # on a plane a rupture zone is an area whose rim the catalog does not keep (only its extents along and across)
    geometries=("chain",), why_not="its classes and rims are the ends of an interval of blocks along a chain")
