"""Figures from one or more summaries: R(mu) of every point overlaid, with bootstrap bands;
recurrence-time distributions, one panel per point, each with its highest peak enlarged in an inset;
the slow side (creep episodes): their size and duration densities, of the points that have any,
and the aseismic slip fraction against the swept parameter; the seismicity around large events,
one map per point: the rate of events at (distance from a mainshock's epicenter, time from its onset)
over the point's background rate, on a logarithmic colour scale centred on 1.
Points of several summaries are labelled by the parameters that differ between all the plotted
points (figure_labels.py: legend_labels, and the title); drawing.py draws the bands and places the insets.

Nothing drawn covers data: legends sit outside the axes, and an inset goes where the panel's
curves and bands stay below it over its whole width (place_inset; tests/test_figures.py checks
every figure in display coordinates). No text is smaller than FONT points."""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from . import summary as summary_file
from .drawing import (DPI, FONT, OPEN, OPEN_NOTE, band, grid, layout, legend_columns, palette, save,
                      place_inset)
from .figure_labels import legend_labels, points_of, summary_name, title_text
from .report import count_text
from .statistics import holds
from .statistics.creep import STATISTIC as CREEP
from .statistics.creep import creeping
from .statistics.seismicity import STATISTIC as SEISMICITY
from .stats import centers


def fault_densities(s, i):
    """R(mu) of each fault of region i of a regional summary, from its own counts in its window, (faults, bins)."""
    edges, counts, n = summary_file.point_units(s, i)
    with np.errstate(invalid="ignore", divide="ignore"):
        return counts.sum(axis=1) / (n.sum(axis=1)[:, None] * np.diff(edges)[None, :])


def magnitude(summaries, ax, keys, labels):
    points = points_of(summaries)
    opened = False
    faults = [(s, i) for s, i in points if "points/region" in s]
    for n, (s, i) in enumerate(faults):   # a region's single faults beneath it, thin and grey
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
    # outside the axes: a legend never covers a curve
    title = "regions (drawn keys; shared values)" if faults else "varying " + ", ".join(keys)
    ax.legend(handles, texts, title=title, fontsize=FONT, title_fontsize=FONT + 1,
              loc="upper left", bbox_to_anchor=(1.01, 1.0), ncol=legend_columns(len(points)))


def _zoom(s, i, x, peak):
    """A drawing function: point i's curves within 6 bins of `peak`."""
    def draw(inset):
        w = 6 * (x[1] - x[0])
        near = (x > peak - w) & (x < peak + w)
        band(inset, x[near], s["points/tnu_density"][i][near], s["points/tnu_lo"][i][near],
             s["points/tnu_hi"][i][near], None, "C0")
        band(inset, x[near], s["points/tnu_interior_density"][i][near],
             s["points/tnu_interior_lo"][i][near], s["points/tnu_interior_hi"][i][near],
             None, "C3", style="--")
        inset.tick_params(labelsize=FONT)
        inset.xaxis.set_major_locator(MaxNLocator(4))
        inset.yaxis.set_major_locator(MaxNLocator(3))
        inset.set_title(f"highest peak, T$\\nu$ = {peak:g}", fontsize=FONT)
    return draw


def recurrence(summaries, fig, labels):
    """The panels (their insets come after the layout: place_insets)."""
    points = points_of(summaries)
    rows, cols = grid(len(points))
    for k, ((s, i), label) in enumerate(zip(points, labels)):
        x = centers(s["bins/tnu"])
        ax = fig.add_subplot(rows, cols, k + 1)
        band(ax, x, s["points/tnu_density"][i], s["points/tnu_lo"][i], s["points/tnu_hi"][i],
             "all large events", "C0")
        band(ax, x, s["points/tnu_interior_density"][i], s["points/tnu_interior_lo"][i],
             s["points/tnu_interior_hi"][i], "interior events (the rupture reaches neither end)", "C3", style="--")
        if "points/numbers/cv_tnu" in s:       # (summaries before format 4 have no intervals statistic)
            label += "\nCV of $T\\nu$ " + interval_text(*s["points/numbers/cv_tnu"][i])
        ax.set_title(label, fontsize=FONT + 1)
        ax.set_xlabel(r"$T\nu$")
        ax.set_ylabel(r"$P(T\nu)$")
        ax.set_xlim(s["bins/tnu"][0], s["bins/tnu"][-1])
        ax.set_ylim(0, ax.get_ylim()[1])
    handles, texts = fig.axes[0].get_legend_handles_labels()
    fig.legend(handles, texts, loc="lower center", ncol=2, fontsize=FONT + 1, frameon=False)


def interval_text(est, lo, hi):
    """'0.84 [0.77, 0.91]' (or the estimate alone, or 'n/a')."""
    if not np.isfinite(est):
        return "n/a"
    return f"{est:.2f} [{lo:.2f}, {hi:.2f}]" if np.isfinite(lo) and np.isfinite(hi) else f"{est:.2f}"


def place_insets(summaries, fig):
    """Each panel's highest peak (the first of the report's `T*nu peaks`: the highest significant peak of the
    smoothed histogram, which may differ from `mode T*nu`, the highest bin) enlarged, where the data are low."""
    renderer = fig.canvas.get_renderer()
    for ax, (s, i) in zip(fig.axes, points_of(summaries)):
        peak = s["points/peaks"][i][0][0]
        if np.isfinite(peak):
            place_inset(ax, _zoom(s, i, centers(s["bins/tnu"]), peak), renderer)


CREEP_PANELS = (   # curve, x label, y label
    ("creep_mu", r"creep episode size $\mu = \log_{10}$ slip", r"density of $\mu$"),
    ("creep_duration", r"creep episode duration $\log_{10}(\mathrm{duration}\;\nu)$", "density"),
)


def creep(summaries, fig, keys, labels, names):
    """Three panels: the creep episodes' size and duration densities of every point that has any
    (overlaid, bands), and the aseismic slip fraction of every point of a summary that reduced the
    creep episodes against the first varying parameter (b if it varies), with its interval."""
    points = points_of(summaries)
    colors = palette(len(points))
    shown = [(s, i, label, color) for (s, i), label, color in zip(points, labels, colors)
             if creeping(s)[i]]
    if not shown:
        raise summary_file.SummaryError(
            f"{', '.join(map(str, names))}: no creep episodes in any point, no creep figure (a summary of "
            "format 2 did not reduce them: reduce its catalogs again)")
    axes = fig.subplots(1, 3)
    opened = False
    for ax, (curve, xlabel, ylabel) in zip(axes, CREEP_PANELS):
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
        if holds(s, CREEP):
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


SEISMICITY_DECADES = 2   # the colour scale of the maps: rate / background from 10^-2 to 10^2


def seismicity(summaries, fig, labels, names):
    """One map per point (the grid of the recurrence panels): log10 of the rate at (distance, time) over the
    point's background rate, white where nothing was exposed; the numbers' regions outlined (near and ring,
    just before and after, some time before)."""
    points = [(s, i, label) for (s, i), label in zip(points_of(summaries), labels) if holds(s, SEISMICITY)]
    if not points:
        raise summary_file.SummaryError(
            f"{', '.join(map(str, names))}: no seismicity around large events (a summary before format 5 did "
            "not reduce it: reduce its catalogs again)")
    rows, cols = grid(len(points))
    mesh = None
    for k, (s, i, label) in enumerate(points):
        ax = fig.add_subplot(rows, cols, k + 1)
        background = s["points/numbers/background_rate"][i][0]
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = np.log10(s["points/seismicity_rate"][i] / background)
        relative = np.where(np.isfinite(relative), relative, np.where(relative == -np.inf, -SEISMICITY_DECADES, np.nan))
        mesh = ax.pcolormesh(s["bins/seis_distance"], s["bins/seis_time"], np.ma.masked_invalid(relative),
                             cmap="RdBu_r", vmin=-SEISMICITY_DECADES, vmax=SEISMICITY_DECADES, shading="flat")
        a = s["attrs"]
        for (d0, d1), (t0, t1), style in ((((0, a["seis_near"]), (-a["seis_short"], a["seis_short"]), "-")),
                                          ((a["seis_near"], a["seis_ring"]), (-a["seis_long"], 0), ":")):
            ax.plot([d0, d1, d1, d0, d0], [t0, t0, t1, t1, t0], style, color="k", lw=0.9)
        ax.axhline(0.0, color="k", lw=0.5, alpha=0.5)
        ax.set_title(f"{label}\n{count_text(s['points/numbers/n_large'][i][0])} mainshocks "
                     f"(mu >= {a['mu_c']:g})", fontsize=FONT + 1)
        ax.set_xlabel("distance from the mainshock's epicenter (blocks)")
        ax.set_ylabel(r"time from its onset, $T\nu$")
        ax.tick_params(labelsize=FONT)
    bar = fig.colorbar(mesh, cax=fig.add_axes([0.89, 0.2, 0.015, 0.6]))
    bar.set_label(r"$\log_{10}$(rate / background rate)", fontsize=FONT + 1)
    bar.ax.tick_params(labelsize=FONT)
    fig.text(0.01, 0.01, "solid: near the epicenter, just before and after the onset; dotted: the ring, "
             "some time before to the onset; white: not observed", fontsize=FONT)


def figure(summaries, kind, title=None, names=None):
    """The figure `kind` ("magnitude", "recurrence", "creep" or "seismicity") of the points of one summary (a dict from
    summary.read) or several (a list), laid out and ready to save. names: the summaries' paths
    or names (to tell points of equal parameters apart)."""
    if isinstance(summaries, dict):
        summaries = [summaries]
    names = ([summary_name(n) for n in names] if names is not None
             else [f"summary {j + 1}" for j in range(len(summaries))])
    keys, labels = legend_labels(summaries, names)
    n = len(labels)
    text = title_text(summaries, names, title, kind)
    if kind == "magnitude":
        fig, ax = plt.subplots(figsize=(8 + 1.6 * (legend_columns(n) - 1), 4.8), dpi=DPI)
        magnitude(summaries, ax, keys, labels)
        layout(fig, text, 0.0)
    elif kind == "creep":
        fig = plt.figure(figsize=(13, 4.6 + 0.25 * math.ceil((n + 1) / 4)), dpi=DPI)
        creep(summaries, fig, keys, labels, names)
        layout(fig, text, 0.45 + 0.2 * math.ceil((n + 1) / 4))   # the figure legend below the panels
    elif kind == "seismicity":
        rows, cols = grid(n)
        fig = plt.figure(figsize=(5.2 * cols + 1.2, 4.2 * rows + 0.8), dpi=DPI)
        fig.subplots_adjust(left=0.09, right=0.86, bottom=(0.55 + 0.3) / fig.get_figheight(),
                            top=1 - 1.1 / fig.get_figheight(), hspace=0.55, wspace=0.3)
        seismicity(summaries, fig, labels, names)
        fig.suptitle(text, fontsize=FONT + 1, wrap=True)
    else:
        rows, cols = grid(n)
        fig = plt.figure(figsize=(5.5 * cols, 4 * rows + 0.4), dpi=DPI)
        recurrence(summaries, fig, labels)
        layout(fig, text, 0.35)      # the figure legend below the panels
        place_insets(summaries, fig)
    return fig


def plot(summaries, figure_kind, path, title=None, names=None):
    """Draw figure(summaries, figure_kind, title, names) into `path`."""
    save(figure(summaries, figure_kind, title, names), path)
