"""Figures from one or more summaries: R(mu) of every point overlaid, with bootstrap bands;
recurrence-time distributions, one panel per point. Points of several summaries are labelled by
the parameters that differ between all the plotted points (legend_labels)."""
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .reduce import PARAMS  # noqa: E402
from .report import level_text, partial_text  # noqa: E402
from .stats import centers  # noqa: E402


def _band(ax, x, y, lo, hi, label, color, log=False, style="-"):
    ok = np.isfinite(y) & ((y > 0) if log else True)
    ax.plot(x[ok], y[ok], style, color=color, label=label, lw=1.4)
    okb = ok & np.isfinite(lo) & np.isfinite(hi)
    if okb.any():
        # on a log axis a lower bound of 0 is drawn down to the axis' bottom
        low = np.where(lo > 0, lo, 1e-300) if log else lo
        ax.fill_between(x[okb], low[okb], hi[okb], color=color, alpha=0.25, lw=0)


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
            rows.append(tuple(None if v != v else v for v in (s[f"points/{k}"][i].item() for k in PARAMS)))
    keys = [k for n, k in enumerate(PARAMS) if len({r[n] for r in rows}) > 1] or ["b"]
    for exact in (False, True):
        labels = [", ".join(f"{k} = {repr(r[PARAMS.index(k)]) if exact else format(r[PARAMS.index(k)], 'g')}"
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


def magnitude(summaries, ax, keys, labels):
    points = _points(summaries)
    for (s, i), label, color in zip(points, labels, _colors(len(points))):
        _band(ax, centers(s["bins/mu"]), s["points/mu_density"][i], s["points/mu_lo"][i],
              s["points/mu_hi"][i], label, color, log=True)
    ax.set_yscale("log")
    density = np.concatenate([s["points/mu_density"].ravel() for s in summaries])
    positive = density[density > 0]
    if positive.size:
        ax.set_ylim(positive.min() / 3, positive.max() * 3)
    ax.set_xlabel(r"magnitude $\mu$")
    ax.set_ylabel(r"$R(\mu)$")
    ax.legend(title="varying " + ", ".join(keys), fontsize=8, ncol=math.ceil(len(points) / 12))


def _grid(n):
    """(rows, columns) of the recurrence panels: two columns, a square grid for many points."""
    cols = min(n, 2) if n <= 6 else math.ceil(math.sqrt(n))
    return math.ceil(n / cols), cols


def recurrence(summaries, fig, labels):
    points = _points(summaries)
    rows, cols = _grid(len(points))
    for k, ((s, i), label) in enumerate(zip(points, labels)):
        x = centers(s["bins/tnu"])
        ax = fig.add_subplot(rows, cols, k + 1)
        _band(ax, x, s["points/tnu_density"][i], s["points/tnu_lo"][i], s["points/tnu_hi"][i],
              "all large events", "C0")
        _band(ax, x, s["points/tnu_interior_density"][i], s["points/tnu_interior_lo"][i],
              s["points/tnu_interior_hi"][i], "interior events", "C3", style="--")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel(r"$T\nu$")
        ax.set_ylabel(r"$P(T\nu)$")
        ax.legend(fontsize=7, loc="upper right")
        peak = s["points/peaks"][i][0][0]
        if np.isfinite(peak):
            inset = ax.inset_axes([0.55, 0.35, 0.4, 0.35])
            w = 6 * (x[1] - x[0])
            near = (x > peak - w) & (x < peak + w)
            _band(inset, x[near], s["points/tnu_density"][i][near], s["points/tnu_lo"][i][near],
                  s["points/tnu_hi"][i][near], None, "C0")
            _band(inset, x[near], s["points/tnu_interior_density"][i][near],
                  s["points/tnu_interior_lo"][i][near], s["points/tnu_interior_hi"][i][near],
                  None, "C3", style="--")
            inset.tick_params(labelsize=6)
            inset.set_title("main peak", fontsize=6)


def title_text(summaries, names, title=None):
    """The figure's title: `title` or the sources and the band level; then one line for each
    partial reduction (events reduced of expected), whatever the title."""
    levels = " / ".join(dict.fromkeys(level_text(s["attrs"]["level"]) for s in summaries))
    if title is None:
        source = (summaries[0]["attrs"]["catalog"] if len(summaries) == 1
                  else ", ".join(names))
        title = f"{source}  (bands: {levels} bootstrap)"
    lines = [title]
    for s, name in zip(summaries, names):
        partial = partial_text(s).split(";")[0]
        if partial:
            lines.append(partial if len(summaries) == 1 else f"{name}: {partial}")
    return "\n".join(lines)


def plot(summaries, figure, path, title=None, names=None):
    """Draw `figure` ("magnitude" or "recurrence") of the points of one summary (a dict from
    summary.read) or several (a list), into `path`. names: the summaries' paths or names."""
    if isinstance(summaries, dict):
        summaries = [summaries]
    names = ([summary_name(n) for n in names] if names is not None
             else [f"summary {j + 1}" for j in range(len(summaries))])
    keys, labels = legend_labels(summaries, names)
    n = len(labels)
    if figure == "magnitude":
        fig, ax = plt.subplots(figsize=(6 + 2 * (math.ceil(n / 12) - 1), 4.5))
        magnitude(summaries, ax, keys, labels)
    else:
        rows, cols = _grid(n)
        fig = plt.figure(figsize=(5.5 * cols, 4 * rows))
        recurrence(summaries, fig, labels)
    fig.suptitle(title_text(summaries, names, title), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
