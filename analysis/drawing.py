"""What every figure of the analysis draws with: the curve with its bootstrap band, colours, the grid of
panels, the title above the panels, and an inset placed where it covers no data (place_inset;
tests/test_figures.py checks every figure in display coordinates). No text is smaller than FONT points."""
import io
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.transforms import Bbox

from ensemble import space

FONT = 8            # the smallest text of a figure, points
INSET = (0.36, 0.34)    # an inset's width and height, fractions of its panel's axes
GAP = 4.0           # points between an inset (with its labels) and the data or the axes' frame
OPEN = "v"          # marker of an interval reaching 0 on a log axis: its upper end
OPEN_NOTE = "interval reaching 0: its upper end"
DPI = 120


def band(ax, x, y, lo, hi, label, color, log=False, style="-", open_ends=False):
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


def palette(n):
    """n colours that can be told apart on white: matplotlib's ten; up to 18, then black and Dark2's seven strong
    ones (no pastel, no pale yellow: neighbours in a sweep never look alike); beyond, viridis without its pale end."""
    strong = [f"C{i}" for i in range(10)] + ["black"] + list(plt.cm.Dark2.colors[:7])
    if n <= len(strong):
        return strong[:n]
    return [plt.cm.viridis(0.88 * i / (n - 1)) for i in range(n)]


def legend_columns(n):
    return math.ceil(n / 16)


def grid(n):
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


def layout(fig, text, bottom):
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


def save(fig, path, dpi=DPI):
    """Draw `fig` into the file `path`, in the format its suffix names (png without one), and close it: drawn in
    memory, then written by space.write_file (never through a link, its blocks reserved first)."""
    image = io.BytesIO()
    try:
        fig.savefig(image, format=os.path.splitext(str(path))[1][1:].lower() or "png", dpi=dpi)
    finally:
        plt.close(fig)
    space.write_file(path, image.getbuffer(), "the figure")
