"""Figures that show their result: on every figure `analysis plot` makes, of the committed
full-size summaries and of synthetic ones built to corner the layout, no inset or legend covers
data (checked in display coordinates on the figure as saved), no text is smaller than 8 pt, the
default title states mu_c, the window and the events per point, and on a log axis an interval
reaching 0 is drawn as its upper end, not as a block down to the axis."""
from pathlib import Path

import numpy as np
import pytest
from matplotlib.text import Text

from analysis import drawing, plot, summary

ROOT = Path(__file__).resolve().parents[1]
PANELS = ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b", "all")
KINDS = ("magnitude", "recurrence")


def _dense(xy, step=0.5):
    """Points along a polyline (display coordinates) at most `step` pixels apart."""
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    out = [xy[:1]]
    for a, b in zip(xy[:-1], xy[1:]):
        n = max(int(np.hypot(*(b - a)) / step), 1)
        out.append(a + (b - a) * np.linspace(0, 1, n + 1)[1:, None])
    return np.concatenate(out) if len(xy) else xy


def _curves(ax):
    """(name, display points) of every curve and band outline drawn in `ax` (not its insets)."""
    out = [(f"line {line.get_label()}", _dense(line.get_transform().transform(np.column_stack(line.get_data()))))
           for line in ax.lines]
    for coll in ax.collections:
        out += [("band", _dense(coll.get_transform().transform(p.vertices))) for p in coll.get_paths()]
    return out


def covered(fig):
    """What the boxes over each panel (its insets with their labels and title, and a legend
    inside it) cover: [(panel title, what, why)]. A box covers a curve when any point of it lies
    above the box's lower edge within the box's width and inside the panel, or when the
    curve's highest point lies inside the box."""
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        if ax in {child for a in fig.axes for child in a.child_axes}:
            continue
        frame = ax.get_window_extent(renderer)
        boxes = [("inset", child.get_tightbbox(renderer)) for child in ax.child_axes]
        if ax.get_legend() is not None:
            box = ax.get_legend().get_window_extent(renderer)
            if box.overlaps(frame):
                boxes.append(("legend", box))
        for what, box in boxes:
            for name, xy in _curves(ax):
                inside = xy[(xy[:, 1] <= frame.y1) & (xy[:, 1] >= frame.y0)]
                above = inside[(inside[:, 0] >= box.x0) & (inside[:, 0] <= box.x1) & (inside[:, 1] >= box.y0)]
                if len(above):
                    found.append((ax.get_title(), what, f"{name}: {len(above)} points above its lower edge"))
                if name.startswith("line") and len(xy):
                    top = xy[np.argmax(xy[:, 1])]
                    if box.contains(*top):
                        found.append((ax.get_title(), what, f"{name}: its maximum inside"))
    return found


def crowded(fig):
    """The title or a figure legend over a panel (its labels and title included)."""
    renderer = fig.canvas.get_renderer()
    children = {child for a in fig.axes for child in a.child_axes}
    panels = [ax.get_tightbbox(renderer) for ax in fig.axes if ax not in children]
    boxes = [("title", fig._suptitle.get_window_extent(renderer))]
    boxes += [("legend", legend.get_window_extent(renderer)) for legend in fig.legends]
    return [(what, k) for what, box in boxes for k, panel in enumerate(panels) if box.overlaps(panel)]


def small_text(fig):
    fig.canvas.draw()
    return [(t.get_text(), t.get_fontsize()) for t in fig.findobj(Text)
            if t.get_visible() and t.get_text().strip() and t.get_fontsize() < 8]


def load(name):
    return summary.read(ROOT / "docs/paper" / f"{name}.summary.h5")


def synthetic(n_points, tnu_curve, mu_curve=None, events=8000, seeds=4):
    """A summary of n_points points with the given curves (functions of the bin centres and the
    point's index), the plotted keys only."""
    tnu_edges, mu_edges = np.linspace(0, 2000, 81), np.linspace(0, 7, 71)
    t, m = 0.5 * (tnu_edges[1:] + tnu_edges[:-1]), 0.5 * (mu_edges[1:] + mu_edges[:-1])
    tnu = np.array([tnu_curve(t, i) for i in range(n_points)])
    mu = np.array([(mu_curve or (lambda m, i: np.exp(-(m - 4) ** 2)))(m, i) for i in range(n_points)])
    s = {"bins/tnu": tnu_edges, "bins/mu": mu_edges,
         "attrs": {"level": 0.95, "mu_c": 4.0, "window": 10, "partial": "", "catalog": "synthetic.h5"},
         "points/method": np.array(["seeds"] * n_points), "points/units": np.full(n_points, seeds),
         "tasks/point": np.repeat(np.arange(n_points), seeds),
         "per_task/numbers": np.zeros((n_points * seeds, 2, 9))}
    s["per_task/numbers"][:, :, 0] = events / seeds / 2
    for k, v in {"N": 800.0, "l": 3.0, "nu": 1e-8, "a": 0.0, "c": 1000.0, "alpha": np.nan, "sigma": np.nan}.items():
        s[f"points/{k}"] = np.full(n_points, v)
    s["points/b"] = 20.0 + 10 * np.arange(n_points)
    for name, curve, bins in (("tnu", tnu, t), ("tnu_interior", 0.6 * tnu, t), ("mu", mu, m)):
        s[f"points/{name}_density"] = curve
        s[f"points/{name}_lo"] = 0.85 * curve
        s[f"points/{name}_hi"] = 1.15 * curve
    # the main peak: the highest bin of each point
    s["points/peaks"] = np.array([[[t[np.argmax(row)], np.nan, np.nan]] for row in tnu])
    return s


def _bump(t, at, width, height):
    return height * np.exp(-0.5 * ((t - at) / width) ** 2)


SYNTHETIC = {
    # a sharp peak where the old inset sat (the right half, mid height) and a broad main peak
    "spike under the old inset": lambda t, i: 1e-4 + _bump(t, 300, 120, 6e-4) + _bump(t, 1100 + 150 * i, 20, 5e-4),
    # high everywhere on the right, the main peak at the left edge
    "high right half": lambda t, i: 1e-4 + _bump(t, 60, 30, 9e-4) + 6e-4 * (t > 900 + 100 * i),
    # a main peak at the right edge and rising noise
    "peak at the right edge": lambda t, i: 2e-4 + t * 1e-7 + _bump(t, 1950 - 100 * i, 25, 1e-3),
    # flat at the top: no room for an inset until the data are lowered
    "flat": lambda t, i: 5e-4 + 1e-5 * np.cos(t / 50) + _bump(t, 700, 10, 6e-5),
}


def _check(fig):
    assert covered(fig) == []
    assert small_text(fig) == []
    assert crowded(fig) == []


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", [pytest.param(p, marks=pytest.mark.slow) if p == "all" else p for p in PANELS])
def test_committed_figures_cover_no_data(name, kind):
    s = load(name)
    fig = plot.figure(s, kind, names=[f"{name}.summary.h5"])
    try:
        _check(fig)
        if kind == "recurrence":   # every panel with a peak has its inset
            assert sum(len(ax.child_axes) for ax in fig.axes) == int(np.isfinite(s["points/peaks"][:, 0, 0]).sum())
        title = fig._suptitle.get_text()
        for words in ("aging law: ", "mu_c = 4", "window = 10 blocks", "events per point", "95% bootstrap"):
            assert words in title, title
        assert name not in title and ".h5" not in title
    finally:
        plot.plt.close(fig)


@pytest.mark.parametrize("kind", KINDS)
def test_overlaid_summaries_cover_no_data(kind):
    """Several summaries in one figure (their points together; 7 recurrence panels on a 3 x 3 grid)."""
    names = ["fig1_b.summary.h5", "large_b.summary.h5"]
    fig = plot.figure([load("fig1_b"), load("large_b")], kind, names=names)
    try:
        _check(fig)
        assert fig._suptitle.get_text().startswith("aging law: 2e5 events per point, mu_c = 4, window = 10 blocks")
    finally:
        plot.plt.close(fig)


@pytest.mark.parametrize("case", sorted(SYNTHETIC))
@pytest.mark.parametrize("n_points", (1, 4))
def test_synthetic_figures_cover_no_data(case, n_points):
    s = synthetic(n_points, SYNTHETIC[case])
    for kind in KINDS:
        fig = plot.figure(s, kind)
        try:
            _check(fig)
            if kind == "recurrence":
                # every panel has its inset (where the data leave no room, they are lowered to make it)
                assert all(ax.child_axes for ax in fig.axes), case
        finally:
            plot.plt.close(fig)
    assert plot.title_text([s], ["x"]) == ("aging law: 8000 events per point (4 seeds x 2000), mu_c = 4, "
                                           "window = 10 blocks; "
                                           "bands: 95% bootstrap over 4 seeds")


def test_the_check_sees_the_old_inset(monkeypatch):
    """The inset where it used to be (right half, 35-70% of the height) covers the sharp peak
    of fig2's b = 40 panels: the check must say so."""
    def old(ax, draw, renderer):
        inset = ax.inset_axes([0.55, 0.35, 0.4, 0.35])
        draw(inset)
        return inset
    monkeypatch.setattr(drawing, "place_inset", old)   # (the recurrence figure takes it from there as it draws)
    fig = plot.figure(load("fig2"), "recurrence")
    try:
        found = covered(fig)
        assert {title for title, _, _ in found} == {"N = 800, b = 40", "N = 1600, b = 40"}, found
    finally:
        plot.plt.close(fig)


def test_log_band_reaching_zero_is_its_upper_end():
    """R(mu) at b = 20 of a reduced run: in the dip the interval's lower end is 0 in some bins.
    Those bins are drawn as a marker at their upper end (explained in the legend); the filled
    band keeps to the bins whose interval is above 0 (no block down to the axis)."""
    def mu_curve(m, i):
        return np.exp(-(m - 4) ** 2)
    s = synthetic(1, SYNTHETIC["flat"], mu_curve)
    dip = (s["bins/mu"][:-1] > 2.3) & (s["bins/mu"][:-1] < 3.5)
    s["points/mu_lo"][0, dip] = 0.0
    fig = plot.figure(s, "magnitude")
    try:
        ax = fig.axes[0]
        marks = [line for line in ax.lines if line.get_marker() == drawing.OPEN]
        assert len(marks) == 1
        x, y = marks[0].get_data()
        c = 0.5 * (s["bins/mu"][1:] + s["bins/mu"][:-1])
        assert np.allclose(x, c[dip]) and np.allclose(y, s["points/mu_hi"][0, dip])
        lowest = s["points/mu_lo"][0][s["points/mu_lo"][0] > 0].min()
        for coll in ax.collections:
            for p in coll.get_paths():
                assert p.vertices[:, 1].min() >= lowest * (1 - 1e-9)
                # no band over the dip's bins
                inner = (p.vertices[:, 0] > c[dip].min() + 1e-9) & (p.vertices[:, 0] < c[dip].max() - 1e-9)
                assert not inner.any()
        assert drawing.OPEN_NOTE in [t.get_text() for t in ax.get_legend().get_texts()]
        _check(fig)
    finally:
        plot.plt.close(fig)
