"""Figures from one or more summaries: R(mu) of every point overlaid, with bootstrap bands;
recurrence-time distributions, one panel per point, each with its main peak enlarged in an inset;
the slow side (creep episodes): their size and duration densities, of the points that have any,
and the aseismic slip fraction against the swept parameter; the seismicity around large events,
one map per point: the rate of events at (distance from a mainshock's epicenter, time from its onset)
over the point's background rate, on a logarithmic colour scale centred on 1.
Points of several summaries are labelled by the parameters that differ between all the plotted
points (legend_labels).

Nothing drawn covers data: legends sit outside the axes, and an inset goes where the panel's
curves and bands stay below it over its whole width (place_inset; tests/test_figures.py checks
every figure in display coordinates). No text is smaller than FONT points."""
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402

from . import summary as summary_file  # noqa: E402
from .reduce import PARAMS  # noqa: E402
from .report import count_text, level_text, partial_text, size_text  # noqa: E402
from .stats import centers  # noqa: E402

FONT = 8            # the smallest text of a figure, points
INSET = (0.36, 0.34)    # an inset's width and height, fractions of its panel's axes
GAP = 4.0           # points between an inset (with its labels) and the data or the axes' frame
OPEN = "v"          # marker of an interval reaching 0 on a log axis: its upper end
OPEN_NOTE = "interval reaching 0: its upper end"
DPI = 120


def _band(ax, x, y, lo, hi, label, color, log=False, style="-", open_ends=False):
    """The curve y(x) and its interval band [lo, hi]. On a log axis a lower bound of 0 has no
    place: with open_ends, such intervals are drawn as their upper end (marker OPEN) and the
    band is filled only where lo > 0; without, the band runs down to the axis' bottom.
    Returns whether any upper end was marked."""
    ok = np.isfinite(y) & ((y > 0) if log else True)
    ax.plot(x[ok], y[ok], style, color=color, label=label, lw=1.4)
    okb = np.isfinite(lo) & np.isfinite(hi) & (True if open_ends else ok)
    if log and open_ends:
        closed = okb & (lo > 0)
        opened = okb & ~(lo > 0) & (hi > 0)
        if closed.any():
            ax.fill_between(x, np.where(closed, lo, np.nan), np.where(closed, hi, np.nan), where=closed,
                            color=color, alpha=0.25, lw=0)
        if opened.any():
            ax.plot(x[opened], hi[opened], OPEN, color=color, ms=4, mew=0.8, mfc="none", ls="none")
        return bool(opened.any())
    if okb.any():
        # on a log axis a lower bound of 0 is drawn down to the axis' bottom
        low = np.where(lo > 0, lo, 1e-300) if log else lo
        ax.fill_between(x[okb], low[okb], hi[okb], color=color, alpha=0.25, lw=0)
    return False


def summary_name(path):
    """A summary's name in labels and titles: its file name without .summary.h5 (or .h5)."""
    base = os.path.basename(str(path))
    return base.removesuffix(".h5").removesuffix(".summary")


def legend_labels(summaries, names=None):
    """(keys, labels) for the points of all `summaries`, in order (summary by summary).

    keys: the parameters that differ between the plotted points (in PARAMS order; ["b"] if
    none do); a label gives their values, e.g. "N = 1600, b = 40" (6 significant digits, or
    all where that is needed to tell two points apart). A point whose parameters appear in
    several summaries gets the summary's name appended, "b = 20 (run2)" (names: one per
    summary, default "summary 1", "summary 2", ...).
    """
    names = list(names) if names is not None else [f"summary {j + 1}" for j in range(len(summaries))]
    owner, rows = [], []
    for j, s in enumerate(summaries):
        for i in range(len(s["points/N"])):
            owner.append(j)
            # None for a key of another friction law (NaN in the summary, which equals nothing)
            rows.append(tuple(None if v != v else v for v in (s[f"points/{k}"][i].item() for k in PARAMS))
                        + (str(summary_file.point_laws(s)[i]),))
    keys = [k for n, k in enumerate(PARAMS) if len({r[n] for r in rows}) > 1] or ["b"]
    laws = len({r[-1] for r in rows}) > 1      # points of several laws: "slip: b = 20"
    for exact in (False, True):
        labels = [(f"{r[-1]}: " if laws else "")
                  + ", ".join(f"{k} = {repr(r[PARAMS.index(k)]) if exact else format(r[PARAMS.index(k)], 'g')}"
                              for k in keys if r[PARAMS.index(k)] is not None) for r in rows]
        if all(labels[a] != labels[b] or rows[a] == rows[b]
               for a in range(len(rows)) for b in range(a)):
            break
    repeated = {r for r in rows if rows.count(r) > 1}
    labels = [f"{label} ({names[j]})" if r in repeated else label
              for label, r, j in zip(labels, rows, owner)]
    return keys, labels


def _points(summaries):
    """[(summary, point index)] of every plotted point."""
    return [(s, i) for s in summaries for i in range(len(s["points/N"]))]


def _colors(n):
    if n <= 10:
        return [f"C{i}" for i in range(n)]
    return [plt.cm.viridis(i / (n - 1)) for i in range(n)]


def _legend_columns(n):
    return math.ceil(n / 16)


def magnitude(summaries, ax, keys, labels):
    points = _points(summaries)
    opened = False
    for (s, i), label, color in zip(points, labels, _colors(len(points))):
        opened |= _band(ax, centers(s["bins/mu"]), s["points/mu_density"][i], s["points/mu_lo"][i],
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
    ax.legend(handles, texts, title="varying " + ", ".join(keys), fontsize=FONT, title_fontsize=FONT + 1,
              loc="upper left", bbox_to_anchor=(1.01, 1.0), ncol=_legend_columns(len(points)))


def _grid(n):
    """(rows, columns) of the recurrence panels: two columns, a square grid for many points."""
    cols = min(n, 2) if n <= 6 else math.ceil(math.sqrt(n))
    return math.ceil(n / cols), cols


def _data_paths(ax):
    """The curves and bands drawn in `ax` (not its insets): (path in display coordinates, filled)."""
    paths = [(line.get_transform().transform_path(line.get_path()), False) for line in ax.lines]
    for coll in ax.collections:   # bands: filled areas
        paths += [(coll.get_transform().transform_path(p), True) for p in coll.get_paths()]
    return paths


def _clear(paths, box):
    return not any(p.intersects_bbox(box, filled=filled) for p, filled in paths)


def place_inset(ax, draw, renderer):
    """Add an inset (drawn by draw(inset)) where the data of `ax` stay below it: the inset with
    its tick labels and title, widened by GAP, and everything above it up to the axes' top
    must not meet a curve or band. Tries 41 positions along the top of the panel and keeps the
    one in the middle of the widest clear stretch; if none is clear, raises the y axis (the data
    shrink downwards) up to three times, then gives up: no inset, the y axis as it was. Returns
    the inset or None."""
    w, h = INSET
    probe = ax.inset_axes([1 - w, 1 - h, w, h])
    draw(probe)
    frame, tight = probe.get_window_extent(renderer), probe.get_tightbbox(renderer)
    probe.remove()
    gap = GAP * ax.figure.dpi / 72
    left, right = frame.x0 - tight.x0 + gap, tight.x1 - frame.x1 + gap
    below, above = frame.y0 - tight.y0 + gap, tight.y1 - frame.y1 + gap
    ylim = ax.get_ylim()
    for raised in range(4):
        if raised:
            ax.set_ylim(ylim[0], ylim[0] + 1.3 ** raised * (ylim[1] - ylim[0]))
        box = ax.get_window_extent(renderer)
        top = box.y1 - above                              # the inset's frame reaches up to here
        y0 = top - h * box.height
        starts = np.linspace(box.x0 + left, box.x1 - right - w * box.width, 41)
        paths = _data_paths(ax)
        clear = [_clear(paths, Bbox([[x - left, y0 - below], [x + w * box.width + right, box.y1]]))
                 for x in starts]
        if any(clear):
            # the widest run of clear positions; the inset in its middle
            runs, start = [], None
            for k, ok in enumerate(clear + [False]):
                if ok and start is None:
                    start = k
                if not ok and start is not None:
                    runs.append((k - start, start, k - 1))
                    start = None
            _, first, last = max(runs, key=lambda r: (r[0], r[2]))
            x = starts[(first + last) // 2]
            to_axes = ax.transAxes.inverted()
            (ax0, ay0), = to_axes.transform([(x, y0)])
            inset = ax.inset_axes([ax0, ay0, w, h])
            draw(inset)
            return inset
    ax.set_ylim(ylim)
    return None


def _zoom(s, i, x, peak):
    """A drawing function: point i's curves within 6 bins of `peak`."""
    def draw(inset):
        w = 6 * (x[1] - x[0])
        near = (x > peak - w) & (x < peak + w)
        _band(inset, x[near], s["points/tnu_density"][i][near], s["points/tnu_lo"][i][near],
              s["points/tnu_hi"][i][near], None, "C0")
        _band(inset, x[near], s["points/tnu_interior_density"][i][near],
              s["points/tnu_interior_lo"][i][near], s["points/tnu_interior_hi"][i][near],
              None, "C3", style="--")
        inset.tick_params(labelsize=FONT)
        inset.xaxis.set_major_locator(MaxNLocator(4))
        inset.yaxis.set_major_locator(MaxNLocator(3))
        inset.set_title(f"main peak, T$\\nu$ = {peak:g}", fontsize=FONT)
    return draw


def recurrence(summaries, fig, labels):
    """The panels (their insets come after the layout: place_insets)."""
    points = _points(summaries)
    rows, cols = _grid(len(points))
    for k, ((s, i), label) in enumerate(zip(points, labels)):
        x = centers(s["bins/tnu"])
        ax = fig.add_subplot(rows, cols, k + 1)
        _band(ax, x, s["points/tnu_density"][i], s["points/tnu_lo"][i], s["points/tnu_hi"][i],
              "all large events", "C0")
        _band(ax, x, s["points/tnu_interior_density"][i], s["points/tnu_interior_lo"][i],
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
    """Each panel's main peak (the highest significant one) enlarged, where the data are low."""
    renderer = fig.canvas.get_renderer()
    for ax, (s, i) in zip(fig.axes, _points(summaries)):
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
    points = _points(summaries)
    colors = _colors(len(points))
    shown = [(s, i, label, color) for (s, i), label, color in zip(points, labels, colors)
             if summary_file.creeping(s)[i]]
    if not shown:
        raise summary_file.SummaryError(
            f"{', '.join(map(str, names))}: no creep episodes in any point, no creep figure (a summary of "
            "format 2 did not reduce them: reduce its catalogs again)")
    axes = fig.subplots(1, 3)
    opened = False
    for ax, (curve, xlabel, ylabel) in zip(axes, CREEP_PANELS):
        for s, i, label, color in shown:
            opened |= _band(ax, centers(s[f"bins/{curve}"]), s[f"points/{curve}_density"][i],
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
        if summary_file.has_creep(s):
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
    points = [(s, i, label) for (s, i), label in zip(_points(summaries), labels) if summary_file.has_seismicity(s)]
    if not points:
        raise summary_file.SummaryError(
            f"{', '.join(map(str, names))}: no seismicity around large events (a summary before format 5 did "
            "not reduce it: reduce its catalogs again)")
    rows, cols = _grid(len(points))
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


def _values(values, fmt="{}"):
    """Distinct values, " / " between them."""
    return " / ".join(dict.fromkeys(fmt.format(v) for v in values))


def _units(s):
    """What a summary's bands resample: "20 stretches", "4 seeds" (or a range of counts)."""
    words = {"blocks": "stretches", "seeds": "seeds"}
    return " / ".join(dict.fromkeys(
        f"{min(n)}-{max(n)} {words[m]}" if min(n) != max(n) else f"{n[0]} {words[m]}"
        for m in dict.fromkeys(s["points/method"])
        for n in [[int(u) for u, k in zip(s["points/units"], s["points/method"]) if k == m]]))


def _creep_sizes(summaries):
    """The creep episodes per point, over the points that have any: "15380-16492 creep episodes per point"."""
    counts = [c for s in summaries if summary_file.has_creep(s)
              for c, creeps in zip(s["points/numbers/n_creep"][:, 0], summary_file.creeping(s)) if creeps]
    if not counts:
        return "no creep episodes"      # (the creep figure then stops with its one-line error)
    lo, hi = min(counts), max(counts)
    return f"{count_text(lo)}{'' if lo == hi else f'-{count_text(hi)}'} creep episodes per point"


def title_text(summaries, names, title=None, kind=None):
    """The figure's title: `title` (then the description below) or by default the description
    alone: events per point, mu_c, window and the bands (never the file names; for the creep
    figure the creep episodes per point and the bands); then one line for each partial reduction
    (events reduced of expected), whatever the title."""
    levels = " / ".join(dict.fromkeys(level_text(s["attrs"]["level"]) for s in summaries))
    bands = f"bands: {levels} bootstrap over {_values(_units(s) for s in summaries)}"
    if kind == "seismicity":   # a map has no band: its numbers (analysis report) have the intervals
        bands = (f"\nmaps without intervals; the numbers' {levels} intervals (analysis report) over "
                 f"{_values(_units(s) for s in summaries)}")
    if kind == "creep":
        description = f"{_creep_sizes(summaries)}; {bands}"
    else:
        description = (f"{_values(size_text(s) for s in summaries)}, "
                       f"mu_c = {_values((s['attrs']['mu_c'] for s in summaries), '{:g}')}, "
                       f"window = {_values((s['attrs']['window'] for s in summaries), '{:g}')} blocks; {bands}")
    partials = []
    for s, name in zip(summaries, names):
        partial = partial_text(s).split(";")[0]
        if partial:
            partials.append(partial if len(summaries) == 1 else f"{name}: {partial}")
    return "\n".join(([description] + partials) if title is None else ([title] + partials + [description]))


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
        fig, ax = plt.subplots(figsize=(8 + 1.6 * (_legend_columns(n) - 1), 4.8), dpi=DPI)
        magnitude(summaries, ax, keys, labels)
        _layout(fig, text, 0.0)
    elif kind == "creep":
        fig = plt.figure(figsize=(13, 4.6 + 0.25 * math.ceil((n + 1) / 4)), dpi=DPI)
        creep(summaries, fig, keys, labels, names)
        _layout(fig, text, 0.45 + 0.2 * math.ceil((n + 1) / 4))   # the figure legend below the panels
    elif kind == "seismicity":
        rows, cols = _grid(n)
        fig = plt.figure(figsize=(5.2 * cols + 1.2, 4.2 * rows + 0.8), dpi=DPI)
        fig.subplots_adjust(left=0.09, right=0.86, bottom=(0.55 + 0.3) / fig.get_figheight(),
                            top=1 - 1.1 / fig.get_figheight(), hspace=0.55, wspace=0.3)
        seismicity(summaries, fig, labels, names)
        fig.suptitle(text, fontsize=FONT + 1, wrap=True)
    else:
        rows, cols = _grid(n)
        fig = plt.figure(figsize=(5.5 * cols, 4 * rows + 0.4), dpi=DPI)
        recurrence(summaries, fig, labels)
        _layout(fig, text, 0.35)      # the figure legend below the panels
        place_insets(summaries, fig)
    return fig


def _layout(fig, text, bottom):
    """The title at the top, the panels below it and `bottom` inches free at the bottom.
    tight_layout leaves room for the title, but not always enough (by a few pixels in a tall
    grid): the panels are then lowered until their titles clear it."""
    title = fig.suptitle(text, fontsize=FONT + 1, wrap=True)
    fig.tight_layout(rect=(0, bottom / fig.get_figheight(), 1, 1))
    renderer = fig.canvas.get_renderer()
    for _ in range(3):
        top = max(ax.get_tightbbox(renderer).y1 for ax in fig.axes)
        short = top + GAP * fig.dpi / 72 - title.get_window_extent(renderer).y0
        if short <= 0:
            break
        fig.subplots_adjust(top=fig.subplotpars.top - short / fig.bbox.height)


def plot(summaries, figure_kind, path, title=None, names=None):
    """Draw figure(summaries, figure_kind, title, names) into `path`."""
    fig = figure(summaries, figure_kind, title, names)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
