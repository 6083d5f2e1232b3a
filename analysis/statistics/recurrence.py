"""Local recurrence times T of large events (analysis/recurrence.py scans them): their distribution, of all
recurrences and of those starting at an interior event, their means and mode, and the significant peaks."""
import numpy as np

from .. import stats
from . import (LAW, Curve, ExportTable, Figure, Number, Option, Statistic, Table, number_lines, number_text,
               report_line)


def feed(acc, rows):
    if rows.recurrences is None:
        return
    block, tnu, interior = rows.recurrences
    edges = rows.opt.tnu_edges
    acc.count("tnu", block, tnu, edges)
    acc.count("tnu_interior", block[interior], tnu[interior], edges)
    acc.add("numbers", "n_rec", block, 1)
    acc.add("numbers", "sum_tnu", block, tnu)
    acc.add("numbers", "n_rec_int", block[interior], 1)
    acc.add("numbers", "sum_tnu_int", block[interior], tnu[interior])


def estimate(u, opt):
    tnu = u["tnu"]
    mode = stats.centers(opt.tnu_edges)[np.argmax(tnu)] if tnu.sum() > 0 else np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        return [u.column("numbers", "n_rec"), u.column("numbers", "sum_tnu") / u.column("numbers", "n_rec"), mode,
                u.column("numbers", "sum_tnu_int") / u.column("numbers", "n_rec_int")]


def peaks(units, opt, rng):
    """Significant recurrence peaks of the merged histogram (stats.find_peaks), each with the
    interval of the nearest peak across bootstrap resamples. Rows: (position, lo, hi).

    The noise of each smoothed bin is the standard deviation of its bootstrap resamples over the
    units, at least the Poisson value (with one unit, or few, the bootstrap understates it).
    """
    tnu_units = units["tnu"]
    total = tnu_units.sum(axis=0)
    noise = stats.poisson_noise(total)
    resampled = None
    if len(tnu_units) >= 2 and total.sum() > 0:
        picks = rng.integers(0, len(tnu_units), size=(opt.bootstrap, len(tnu_units)))
        resampled = np.array([tnu_units[p].sum(axis=0) for p in picks])
        spread = np.array([stats.smooth(c) for c in resampled]).std(axis=0, ddof=1)
        noise = np.maximum(noise, spread)
    base = stats.find_peaks(total, opt.tnu_edges, noise)
    if len(base) == 0 or resampled is None:
        return {"peaks": np.array([[p, np.nan, np.nan] for p in base]).reshape(-1, 3)}
    width = opt.tnu_edges[1] - opt.tnu_edges[0]
    found = [[] for _ in base]
    for counts in resampled:
        near_peaks = stats.find_peaks(counts, opt.tnu_edges, noise)
        for i, b in enumerate(base):
            if len(near_peaks):
                near = near_peaks[np.argmin(np.abs(near_peaks - b))]
                if abs(near - b) <= 5 * width:
                    found[i].append(near)
    rows = []
    for b, f in zip(base, found):
        lo, hi = (np.percentile(f, [50 * (1 - opt.level), 100 - 50 * (1 - opt.level)])
                  if len(f) else (np.nan, np.nan))
        rows.append([b, lo, hi])
    return {"peaks": np.array(rows)}


def report(s, i):
    """Its numbers, then the significant peaks of point i, each with its interval."""
    peaks = [row for row in s["points/peaks"][i] if np.isfinite(row[0])]
    return number_lines(STATISTIC, s, i) + [report_line("T*nu peaks", "; ".join(number_text(*row) for row in peaks)
                                                        or "-")]


def peaks_table(s):
    """The peaks of every point, highest first (ExportTable.build)."""
    from ..summary import DATASETS
    peaks = s["points/peaks"]
    point, rank = np.nonzero(np.isfinite(peaks[..., 0]))
    values = {"point": point.astype(np.int64), "peak": rank.astype(np.int64),
              "tnu": peaks[point, rank, 0], "tnu_lo": peaks[point, rank, 1], "tnu_hi": peaks[point, rank, 2]}
    unit = DATASETS["points/peaks"][0]
    columns = {
        "point": ("index", "parameter point (row of numbers.csv)"),
        "peak": ("index", "0 for the highest peak of the point, 1 for the next, ..."),
        "tnu": (unit, "T nu at the peak (centre of its bin in the smoothed histogram)"),
        "tnu_lo": (unit, "lower end of its bootstrap interval (NaN with one unit or no match)"),
        "tnu_hi": (unit, "upper end of its bootstrap interval (NaN with one unit or no match)"),
    }
    return columns, values


def _zoom(s, i, x, peak):
    """A drawing function: point i's curves within 6 bins of `peak`."""
    from matplotlib.ticker import MaxNLocator

    from ..drawing import FONT, band

    def draw_inset(inset):
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
    return draw_inset


def figure_size(n):
    from ..drawing import grid
    rows, cols = grid(n)
    return 5.5 * cols, 4 * rows + 0.4


def draw(summaries, fig, keys, labels, names, title):
    """One panel per point: the distribution of all recurrences and of those starting at an interior event, with
    bands, its CV in the title; after the layout, each panel's highest peak (the first of the report's `T*nu
    peaks`: the highest significant peak of the smoothed histogram, which may differ from `mode T*nu`, the highest
    bin) enlarged in an inset where the data are low (drawing.place_inset)."""
    from ..drawing import FONT, band, grid, layout, place_inset
    from ..figure_labels import points_of
    from ..stats import centers
    points = points_of(summaries)
    rows, cols = grid(len(points))
    for k, ((s, i), label) in enumerate(zip(points, labels)):
        x = centers(s["bins/tnu"])
        ax = fig.add_subplot(rows, cols, k + 1)
        band(ax, x, s["points/tnu_density"][i], s["points/tnu_lo"][i], s["points/tnu_hi"][i],
             "all large events", "C0")
        band(ax, x, s["points/tnu_interior_density"][i], s["points/tnu_interior_lo"][i],
             s["points/tnu_interior_hi"][i], "interior events (the rupture reaches "
             + ("no edge)" if "points/geometry" in s else "neither end)"), "C3", style="--")
        if "points/numbers/cv_tnu" in s:       # (summaries before format 4 have no intervals statistic)
            label += "\nCV of $T\\nu$ " + number_text(*s["points/numbers/cv_tnu"][i], digits=".2f", missing="n/a")
        ax.set_title(label, fontsize=FONT + 1)
        ax.set_xlabel(r"$T\nu$")
        ax.set_ylabel(r"$P(T\nu)$")
        ax.set_xlim(s["bins/tnu"][0], s["bins/tnu"][-1])
        ax.set_ylim(0, ax.get_ylim()[1])
    handles, texts = fig.axes[0].get_legend_handles_labels()
    fig.legend(handles, texts, loc="lower center", ncol=2, fontsize=FONT + 1, frameon=False)
    layout(fig, title, 0.35)      # the figure legend below the panels
    renderer = fig.canvas.get_renderer()
    for ax, (s, i) in zip(fig.axes, points):
        peak = s["points/peaks"][i][0][0]
        if np.isfinite(peak):
            place_inset(ax, _zoom(s, i, centers(s["bins/tnu"]), peak), renderer)


STATISTIC = Statistic(
    "recurrence", 20, needs=("recurrences",),
    tables=(Table("tnu", "count", "recurrences per T nu bin, per task and stretch of their starting event", bins="tnu"),
            Table("tnu_interior", "count", "the same for the recurrences starting at an interior event", bins="tnu"),
            Table("numbers", "count or sum", "counts and sums of the recurrences",
                  columns=("n_rec", "sum_tnu", "n_rec_int", "sum_tnu_int"))),
    numbers=(Number("n_recurrences", "count", "recurrences: large events closed by a later one within `window` blocks",
                    "recurrences"),
             Number("mean_tnu", "model length", "mean T nu of all recurrences", "mean T*nu"),
             Number("mode_tnu", "model length", "centre of the highest T nu bin", "mode T*nu"),
             Number("mean_tnu_interior", "model length", "mean T nu of the recurrences starting at an interior event",
                    "mean T*nu (int.)")),
    curves=(Curve("tnu", "tnu", ("numbers", "n_rec"), "T nu", "all recurrences", "1/model length"),
            Curve("tnu_interior", "tnu_interior", ("numbers", "n_rec_int"), "T nu",
                  "the recurrences starting at an interior event (boundary false)", "1/model length")),
    feed=feed, estimate=estimate, extra=peaks, report=report,
    exports=(ExportTable("peaks", "one row per recurrence peak of a point", peaks_table),),
    figures=(Figure("recurrence", "the recurrence-time distributions, one panel per point, each with its highest "
                                  "peak enlarged in an inset", figure_size, draw),),
    options=(Option("tnu_bins", "bins", LAW, "model length", "T*nu bins lo:hi:n"),
             Option("window", "count", 10, "blocks", "epicenter window in blocks", 0, 10 ** 9)),
    extra_datasets={"peaks": ("model length", "(points, most peaks, 3): position, lo, hi; NaN rows pad",
                              "recurrence peaks of the T nu histogram, highest first (analysis/stats.py find_peaks)")})
