"""The magnitude distribution R(mu) of the inertial events, and the share of large ones (mu >= mu_c)."""
import numpy as np

from . import LAW, Criterion, Curve, Figure, Number, Option, Statistic, Table

MAGNITUDE = (-330.0, 310.0)    # log10 of a float64 slip: every magnitude lies here


def feed(acc, rows):
    if rows.ev is None:
        return
    mu = rows.ev["mu"]
    acc.count("mu", rows.block, mu, rows.opt.mu_edges)
    acc.add("numbers", "n_events", rows.block, 1)
    acc.add("numbers", "n_large", rows.block, mu >= rows.opt.mu_c)


def estimate(u, opt):
    n, large = u.column("numbers", "n_events"), u.column("numbers", "n_large")
    with np.errstate(invalid="ignore", divide="ignore"):
        return [n, large, large / n]


def fault_densities(s, i):
    """R(mu) of each fault of region i of a regional summary, from its own counts in its window, (faults, bins)."""
    from ..summary import point_units
    edges, counts, n = point_units(s, i)
    with np.errstate(invalid="ignore", divide="ignore"):
        return counts.sum(axis=1) / (n.sum(axis=1)[:, None] * np.diff(edges)[None, :])


def figure_size(n):
    from ..drawing import legend_columns
    return 8 + 1.6 * (legend_columns(n) - 1), 4.8


def draw(summaries, fig, keys, labels, names, title):
    """R(mu) of every point overlaid, with its band (a region's single faults beneath it, thin and grey); the legend
    outside the axes, where it never covers a curve."""
    from matplotlib.lines import Line2D

    from ..drawing import FONT, OPEN, OPEN_NOTE, band, layout, legend_columns, palette
    from ..figure_labels import points_of
    from ..stats import centers
    ax = fig.add_subplot()
    points = points_of(summaries)
    opened = False
    faults = [(s, i) for s, i in points if "points/region" in s]
    for n, (s, i) in enumerate(faults):
        for k, curve in enumerate(fault_densities(s, i)):
            shown = curve > 0
            ax.plot(centers(s["bins/mu"])[shown], curve[shown], color="0.6", lw=0.5, alpha=0.5, zorder=1,
                    label="single faults (in the window)" if n == k == 0 else None)
    for (s, i), label, color in zip(points, labels, palette(len(points))):
        opened |= band(ax, centers(s["bins/mu"]), s["points/mu_density"][i], s["points/mu_lo"][i],
                       s["points/mu_hi"][i], label, color, log=True, open_ends=True)
    ax.set_yscale("log")
    density = np.concatenate([s["points/mu_density"].ravel() for s in summaries])
    positive = density[density > 0]
    if positive.size:
        ax.set_ylim(positive.min() / 3, positive.max() * 3)
    ax.set_xlabel(r"magnitude $\mu$")
    ax.set_ylabel(r"$R(\mu)$")
    handles, texts = ax.get_legend_handles_labels()
    if opened:
        handles.append(Line2D([], [], marker=OPEN, color="0.3", mfc="none", ls="none"))
        texts.append(OPEN_NOTE)
    heading = "regions (drawn keys; shared values)" if faults else "varying " + ", ".join(keys)
    ax.legend(handles, texts, title=heading, fontsize=FONT, title_fontsize=FONT + 1,
              loc="upper left", bbox_to_anchor=(1.01, 1.0), ncol=legend_columns(len(points)))
    layout(fig, title, 0.0)


STATISTIC = Statistic(
    "magnitude", 10,
    tables=(Table("mu", "count", "events per magnitude bin, per task and stretch", bins="mu"),
            Table("numbers", "count or sum", "counts and sums of the inertial events",
                  columns=("n_events", "n_large"))),
    numbers=(Number("n_events", "count",
                    "inertial events (/events/kind 0: creep episodes are in none of these numbers)", "events"),
             Number("n_large", "count", "large events (mu >= mu_c)", "large"),
             Number("fraction_large", "1", "fraction of the events with mu >= mu_c", "frac(mu>=mu_c)")),
    curves=(Curve("mu", "mu", ("numbers", "n_events"), "mu", "all events", "1/mu"),),
    feed=feed, estimate=estimate, sets=("reduce", "compare"),
    figures=(Figure("magnitude", "R(mu) of every point overlaid, with bootstrap bands", figure_size, draw),),
    options=(Option("mu_bins", "bins", LAW, "log10 model length", "magnitude bins lo:hi:n",
                    # the comparison's laws have magnitudes on different scales: one axis spans them
                    defaults={"compare": "-4:7:110"}),
             Option("mu_c", "number", LAW, "log10 model length", "large-event magnitude", *MAGNITUDE,
                    # only the share of large events reads it there, which the comparison does not report
                    defaults={"compare": 4.0})),
    criteria=(Criterion("mu", "mu", "mu_c"),))
