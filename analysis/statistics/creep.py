"""The slow side: the creep episodes (/events/kind 1, below the block stiffness), their size and duration
densities, their share of the rows, the share taken over by an inertial event, and the aseismic slip fraction."""
import math

import numpy as np

from ensemble.store import schema

from . import Curve, Figure, Number, Option, Statistic, Table, holds, number_lines, report_line


def feed(acc, rows):
    if rows.ev is not None:
        acc.add("creep", "sum_slip_events", rows.block, rows.ev["slip"])
    if rows.creep_block is None:
        return
    part, creep, block = rows.part, rows.creep, rows.creep_block
    with np.errstate(divide="ignore"):      # a duration of 0 is out of every bin (still counted)
        log_duration = np.log10(part["duration"][creep] * rows.nu)
    acc.count("creep_mu", block, part["mu"][creep], rows.opt.creep_mu_edges)
    acc.count("creep_duration", block, log_duration, rows.opt.creep_duration_edges)
    acc.add("creep", "n_creep", block, 1)
    acc.add("creep", "n_creep_taken_over", block, part["ending"][creep] == schema.ENDING_TAKEN_OVER)
    acc.add("creep", "sum_slip_creep", block, part["slip"][creep])


def estimate(u, opt):
    n, taken, slow, fast = (u.column("creep", c) for c in ("n_creep", "n_creep_taken_over", "sum_slip_creep",
                                                          "sum_slip_events"))
    with np.errstate(invalid="ignore", divide="ignore"):
        return [n, n / (n + u.column("numbers", "n_events")), taken / n, slow / (slow + fast)]


def creeping(s):
    """(points,) bool: the points of summary `s` (as read) with creep episodes (none in a summary without them)."""
    if not holds(s, STATISTIC):
        return np.zeros(len(s["points/N"]), dtype=bool)
    return s["points/numbers/n_creep"][:, 0] > 0


def report(s, i):
    """Point i's slow side: its numbers with intervals, one line saying it has no creep episodes, or nothing for a
    summary that did not reduce them (format 2)."""
    if not holds(s, STATISTIC):
        return []
    if not creeping(s)[i]:
        return [report_line("creep episodes", "none")]
    return number_lines(STATISTIC, s, i)


PANELS = (   # curve, x label, y label
    ("creep_mu", r"creep episode size $\mu = \log_{10}$ slip", r"density of $\mu$"),
    ("creep_duration", r"creep episode duration $\log_{10}(\mathrm{duration}\;\nu)$", "density"),
)


def _legend_rows(n):
    return math.ceil((n + 1) / 4)


def figure_size(n):
    return 13, 4.6 + 0.25 * _legend_rows(n)


def describe(summaries):
    """The title's words: the creep episodes per point, over the points that have any."""
    from ..report import count_text
    counts = [s["points/numbers/n_creep"][i, 0] for s in summaries for i in np.flatnonzero(creeping(s))]
    if not counts:
        return "no creep episodes"      # (the figure then stops with its one-line error)
    lo, hi = min(counts), max(counts)
    return f"{count_text(lo)}{'' if lo == hi else f'-{count_text(hi)}'} creep episodes per point"


def draw(summaries, fig, keys, labels, names, title):
    """Three panels: the creep episodes' size and duration densities of every point that has any (overlaid, bands),
    and the aseismic slip fraction of every point of a summary that reduced the creep episodes against the first
    varying parameter (b if it varies), with its interval."""
    from matplotlib.lines import Line2D

    from ..drawing import FONT, OPEN, OPEN_NOTE, band, layout, palette
    from ..figure_labels import points_of
    from ..stats import centers
    from ..summary import SummaryError
    points = points_of(summaries)
    colors = palette(len(points))
    shown = [(s, i, label, color) for (s, i), label, color in zip(points, labels, colors) if creeping(s)[i]]
    if not shown:
        raise SummaryError(f"{', '.join(map(str, names))}: no creep episodes in any point, no creep figure (a summary "
                           "of format 2 did not reduce them: reduce its catalogs again)")
    axes = fig.subplots(1, 3)
    opened = False
    for ax, (curve, xlabel, ylabel) in zip(axes, PANELS):
        for s, i, label, color in shown:
            opened |= band(ax, centers(s[f"bins/{curve}"]), s[f"points/{curve}_density"][i],
                           s[f"points/{curve}_lo"][i], s[f"points/{curve}_hi"][i], label, color,
                           log=True, open_ends=True)
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
    x_key = "b" if "b" in keys else keys[0]
    others = [k for k in keys if k != x_key]
    ax = axes[2]
    series = {}
    for s, i in points:
        if holds(s, STATISTIC):
            group = ", ".join(f"{k} = {s[f'points/{k}'][i]:g}" for k in others)
            series.setdefault(group, []).append((s[f"points/{x_key}"][i], *s["points/numbers/aseismic_fraction"][i]))
    for n, (group, rows) in enumerate(series.items()):
        x, y, lo, hi = np.array(sorted(rows)).T
        err = np.where(np.isfinite(lo), [y - lo, hi - y], 0.0)
        ax.errorbar(x, y, yerr=err, fmt="o-", color=f"C{n % 10}", ms=4, capsize=3, lw=1.2, clip_on=False,
                    label=group or None)
    ax.set_ylim(0, ax.get_ylim()[1])
    ax.set_xlabel(x_key)
    ax.set_ylabel("aseismic slip fraction")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    if len(series) > 1:
        ax.legend(fontsize=FONT, loc="upper center", bbox_to_anchor=(0.5, -0.22), frameon=False)
    handles, texts = axes[0].get_legend_handles_labels()
    if opened:
        handles.append(Line2D([], [], marker=OPEN, color="0.3", mfc="none", ls="none"))
        texts.append(OPEN_NOTE)
    fig.legend(handles, texts, title="varying " + ", ".join(keys), loc="lower center", fontsize=FONT,
               title_fontsize=FONT + 1, ncol=min(len(texts), 4), frameon=False)
    layout(fig, title, 0.45 + 0.2 * _legend_rows(len(labels)))   # the figure legend below the panels


STATISTIC = Statistic(
    "creep", 40,
    tables=(Table("creep_mu", "count",
                  "creep episodes per mu bin, per task and stretch (of the inertial events before them)",
                  bins="creep_mu"),
            Table("creep_duration", "count", "creep episodes per log10(duration nu) bin, per task and stretch",
                  bins="creep_duration"),
            Table("creep", "count or sum",
                  "counts and sums of the slow side (sum_slip_events: the inertial events' slip)",
                  columns=("n_creep", "n_creep_taken_over", "sum_slip_creep", "sum_slip_events"))),
    numbers=(Number("n_creep", "count", "creep episodes (/events/kind 1, below the block stiffness 1 + 2 l^2)",
                    "creep episodes"),
             Number("creep_share", "1", "share of the rows that are creep episodes: n_creep / (n_creep + n_events)",
                    "creep share (rows)"),
             Number("taken_over_share", "1", "share of the creep episodes taken over by an inertial event "
                                             "(/events/ending 2); NaN without creep episodes", "taken over"),
             Number("aseismic_fraction", "1", "aseismic slip fraction (1 - seismic coupling): the slip of the creep "
                                              "episodes over all slip (creep episodes and inertial events) after the "
                                              "transient", "aseismic fraction")),
    curves=(Curve("creep_mu", "creep_mu", ("creep", "n_creep"), "mu",
                  "the creep episodes (/events/kind 1; mu = log10 of the slip creep released)", "1/mu"),
            Curve("creep_duration", "creep_duration", ("creep", "n_creep"), "log10(duration nu)",
                  "the creep episodes (duration in units of the loading time 1/nu)", "1/log10 unit")),
    feed=feed, estimate=estimate, uses_tables=("numbers",), report=report,
    figures=(Figure("creep", "the creep episodes' size and duration densities and the aseismic slip fraction "
                             "(points with creep episodes; an error if none has any)", figure_size, draw,
                    describe=describe),),
    # the default bins: measured at N = 100, b = 8..18.5 (aging law), creep slips reach mu = -11 and durations
    # 10^-6.4 / nu
    options=(Option("creep_mu_bins", "bins", "-12:3:75", "log10 model length",
                    "bins lo:hi:n of the creep episodes' mu = log10(slip) (a negative lo after '=': "
                    "--creep-mu-bins=-8:2:50)"),
             Option("creep_duration_bins", "bins", "-7:3:50", "log10(duration nu)",
                    "bins lo:hi:n of the creep episodes' log10(duration nu), duration in units of the loading "
                    "time 1/nu")))
