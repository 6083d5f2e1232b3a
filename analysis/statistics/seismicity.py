"""Seismicity around large events: the events before and after each mainshock (an inertial event with
mu >= mu_c), stacked by their time from its onset and their distance from its epicenter.

Every pair (mainshock m, inertial event i != m of the same task, of any size, a mainshock too) with
dt = T_i - T_m in the time bins (T = t nu, the loader's displacement; negative dt: before the mainshock)
and d = |epicenter_i - epicenter_m| in the distance bins (blocks; on a plane the Euclidean distance in block
units between the epicenters, sqrt(dx^2 + dy^2) with dx along strike and dy across) is counted in the 2-d histogram
`seis_pairs` (time bins x distance bins), in the stretch of the mainshock. Pairs are found across the
chunks in which a task streams: the events of the last max(|lo|, |hi|) of T nu are carried to the next
chunk, and a pair is counted in the chunk of its later event.

The rates are honest about what was observed: a mainshock's exposure in a cell (time bin j, distance
bin k) is the time of bin j that lies within the task's observed span [T of its first inertial event,
T of its last] (a window cut by the start or the end of the task's rows counts only what it covers),
times the number of blocks of the chain (0 .. N-1) at a distance in bin k of the epicenter (fewer near
the chain's ends; on a plane the blocks of the N x M plane at a Euclidean distance in bin k, fewer near its
edges). A mainshock's exposure is added when its window has been seen to its end, or with
the task's last inertial event; so it is added once, the same way whatever the chunks. The map is the
counts over the summed exposures: events per mainshock per block per unit T nu, like the background
rate: every inertial event after the task's first, over the blocks of the chain (N M of a plane) times the
task's span. One row (a chain) keeps its own kernels (count_pairs, expose), a plane has its own
(count_pairs_plane, expose_plane): _kernels, by the task's Shape.

The numbers take the cells whose bins lie wholly within a region (options seis_near, seis_ring,
seis_short, seis_long: put them on the bins' edges): near = distance < seis_near, ring = seis_near <=
distance < seis_ring; just before = [-seis_short, 0), just after = [0, seis_short), some time before =
[-seis_long, -seis_short). A rate of a region is its counts over its exposures, summed over its cells.
"""
import functools

import numba as nb
import numpy as np

import ensemble.model  # noqa: F401  (first: numba caches the kernel in the package's cache, ensemble/kernel_cache.py)

from .. import geometry
from . import ExportTable, Figure, Number, Option, Statistic, Table, holds

NAME = "seismicity"
_EDGE = 1e-9    # a region's bound matches a bin edge within this share of the bin's width


@nb.njit(cache=True)
def count_pairs(T, epicenter, main, stretch, n_old, time_edges, distance_bin, out):
    """Count into out (stretches, time bins * distance bins) every pair (mainshock m, event i != m) of
    the events T (T nu, in time order), epicenter, main (mu >= mu_c), stretch (of each event) with
    dt = T[i] - T[m] in [time_edges[0], time_edges[-1]) and its distance d = |epicenter[i] - epicenter[m]|
    in a distance bin (distance_bin[d], -1: none), of which at least one of m, i is new (index >= n_old: the
    events before are the carried ones, whose pairs among themselves were counted before)."""
    lo, hi = time_edges[0], time_edges[-1]
    n = T.shape[0]
    for m in range(n):
        if not main[m]:
            continue
        if m >= n_old:   # the events before m: old or new, one of the pair is new
            i = m - 1
            while i >= 0 and T[i] - T[m] >= lo:
                _add(T[i] - T[m], distance_bin[abs(epicenter[i] - epicenter[m])], stretch[m], time_edges, out)
                i -= 1
        i = max(m + 1, n_old)
        while i < n and T[i] - T[m] < hi:
            _add(T[i] - T[m], distance_bin[abs(epicenter[i] - epicenter[m])], stretch[m], time_edges, out)
            i += 1


@nb.njit(cache=True)
def _add(dt, k, s, time_edges, out):
    n_time = time_edges.shape[0] - 1
    if k < 0 or dt < time_edges[0] or dt >= time_edges[n_time]:
        return
    # the time bin j with time_edges[j] <= dt < time_edges[j + 1]: guessed as if the bins were even, then
    # moved to the edges themselves (the same bin as a search of the edges, for any edges)
    j = min(max(int((dt - time_edges[0]) / (time_edges[n_time] - time_edges[0]) * n_time), 0), n_time - 1)
    while time_edges[j] > dt:
        j -= 1
    while time_edges[j + 1] <= dt:
        j += 1
    out[s, j * (out.shape[1] // n_time) + k] += 1


def distance_bins(n_blocks, distance_edges):
    """The distance bin of each distance 0 .. n_blocks - 1 (blocks; -1: in none)."""
    k = np.searchsorted(distance_edges, np.arange(n_blocks), side="right") - 1
    return np.where(k < len(distance_edges) - 1, k, -1).astype(np.int64)


@nb.njit(cache=True)
def expose(T, x, s, start, end, n_blocks, time_edges, distance_edges, out):
    """Add to out (stretches, time bins * distance bins) the exposure of each mainshock (onset T, epicenter x,
    stretch s), one after the other: the T nu of each time bin of its window within [start, end] times the
    blocks 0 .. n_blocks - 1 at a distance in each distance bin of x (|j - x| < D counts the integers j in
    (x - D, x + D), clipped to the chain)."""
    n_distance = distance_edges.shape[0] - 1
    space = np.empty(n_distance)
    for m in range(T.shape[0]):
        below = 0.0
        for k in range(n_distance + 1):
            D = distance_edges[k]
            within = 0.0
            if D > 0:
                lo = max(np.floor(x[m] - D) + 1, 0.0)
                hi = min(np.ceil(x[m] + D) - 1, n_blocks - 1.0)
                within = max(hi - lo + 1, 0.0)
            if k > 0:
                space[k - 1] = within - below
            below = within
        _spread(T[m], s[m], start, end, time_edges, space, out)


@nb.njit(cache=True)
def _spread(T, s, start, end, time_edges, space, out):
    """Add one mainshock's exposure (onset T, stretch s) to out: the T nu of each time bin of its window within
    [start, end] times its blocks in each distance bin (space)."""
    n_time, n_distance = time_edges.shape[0] - 1, space.shape[0]
    for j in range(n_time):
        a, b = T + time_edges[j], T + time_edges[j + 1]
        cover = max(min(b, end) - max(a, start), 0.0)
        for k in range(n_distance):
            out[s, j * n_distance + k] += cover * space[k]


@nb.njit(cache=True)
def _plane_bin(dx, dy, distance_edges):
    """The distance bin of a block dx along and dy across strike from the epicenter (-1: in none)."""
    k = np.searchsorted(distance_edges, np.sqrt(float(dx * dx + dy * dy)), side="right") - 1
    return k if k < distance_edges.shape[0] - 1 else -1


@nb.njit(cache=True)
def count_pairs_plane(T, x, y, main, stretch, n_old, time_edges, distance_edges, out):
    """count_pairs on a plane: the epicenters at (x along, y across strike), a pair's distance Euclidean in block
    units, binned by its own search of the distance edges."""
    lo, hi = time_edges[0], time_edges[-1]
    n = T.shape[0]
    for m in range(n):
        if not main[m]:
            continue
        if m >= n_old:
            i = m - 1
            while i >= 0 and T[i] - T[m] >= lo:
                _add(T[i] - T[m], _plane_bin(x[i] - x[m], y[i] - y[m], distance_edges), stretch[m], time_edges, out)
                i -= 1
        i = max(m + 1, n_old)
        while i < n and T[i] - T[m] < hi:
            _add(T[i] - T[m], _plane_bin(x[i] - x[m], y[i] - y[m], distance_edges), stretch[m], time_edges, out)
            i += 1


@nb.njit(cache=True)
def expose_plane(T, x, y, s, start, end, n_along, n_across, time_edges, distance_edges, out):
    """expose on a plane of n_along x n_across blocks: each mainshock's blocks in each distance bin counted one by
    one (those within the last edge: a square of its side around the epicenter, cut by the plane's edges), binned
    as the pairs are (_plane_bin)."""
    n_distance = distance_edges.shape[0] - 1
    space = np.empty(n_distance)
    reach = int(np.ceil(min(distance_edges[n_distance], float(n_along + n_across))))
    for m in range(T.shape[0]):
        space[:] = 0.0
        for i in range(max(y[m] - reach, 0), min(y[m] + reach, n_across - 1) + 1):
            for j in range(max(x[m] - reach, 0), min(x[m] + reach, n_along - 1) + 1):
                k = _plane_bin(j - x[m], i - y[m], distance_edges)
                if k >= 0:
                    space[k] += 1.0
        _spread(T[m], s[m], start, end, time_edges, space, out)


def _chain_pairs(T, epicenter, main, stretch, n_old, opt, shape, out):
    count_pairs(T, epicenter, main, stretch, n_old, opt.seis_time_edges,
                distance_bins(max(shape.n_blocks, int(epicenter.max()) + 1), opt.seis_distance_edges), out)


def _plane_pairs(T, epicenter, main, stretch, n_old, opt, shape, out):
    x, y = shape.position(epicenter)
    count_pairs_plane(T, x, y, main, stretch, n_old, opt.seis_time_edges, opt.seis_distance_edges, out)


def _chain_expose(T, epicenter, s, start, end, opt, shape, out):
    expose(T, epicenter, s, start, end, shape.n_blocks, opt.seis_time_edges, opt.seis_distance_edges, out)


def _plane_expose(T, epicenter, s, start, end, opt, shape, out):
    x, y = shape.position(epicenter)
    expose_plane(T, x, y, s, start, end, shape.N, shape.M, opt.seis_time_edges, opt.seis_distance_edges, out)


def _kernels(shape):
    """(count the pairs, add the exposures) of a task's Shape, each taking the epicenters' block indices and the
    Shape: one row's own (a chain's numbers as before, bit for bit), else the plane's."""
    return (_chain_pairs, _chain_expose) if shape.one_row else (_plane_pairs, _plane_expose)


def _expose(acc, carry, take, end, opt):
    """Add the exposures of the pending mainshocks `take` (a mask, in time order) with the span ending at `end`,
    one after the other (the sums are the same whatever the chunks)."""
    _kernels(carry["shape"])[1](carry["pending_T"][take], carry["pending_x"][take],
                                carry["pending_s"][take].astype(np.int64), carry["start"], end, opt, carry["shape"],
                                acc["seis_exposure"])


def feed(acc, rows):
    if rows.ev is None:
        return
    opt = rows.opt
    edges = opt.seis_time_edges
    T = rows.ev["t"] * rows.nu
    x = rows.ev["epicenter"].astype(np.int64)
    main = rows.ev["mu"] >= opt.mu_c
    carry = acc.carry.get(NAME)
    if carry is None:   # the task's first inertial event opens its span
        carry = acc.carry[NAME] = {
            "start": T[0], "shape": rows.shape or geometry.shape(rows.n_blocks), "T": T[:0], "x": x[:0],
            "main": main[:0], "s": rows.block[:0],
            "pending_T": T[:0], "pending_x": x[:0], "pending_s": rows.block[:0]}
    # the background: every event after the task's first closes a gap of the whole fault (chain or plane)
    t = np.concatenate([[rows.t_before], rows.ev["t"]])
    gap = np.diff(t) * rows.nu
    first = 0 if np.isfinite(rows.t_before) else 1
    acc.add(NAME, "n_gaps", rows.block[first:], 1)
    acc.add(NAME, "block_span", rows.block[first:], gap[first:] * rows.n_blocks)
    acc.add(NAME, "n_main", rows.block[main], 1)
    # the pairs: the carried events, then this chunk's
    n_old = len(carry["T"])
    allT = np.concatenate([carry["T"], T])
    allx = np.concatenate([carry["x"], x])
    allm = np.concatenate([carry["main"], main])
    alls = np.concatenate([carry["s"], rows.block])
    _kernels(carry["shape"])[0](allT, allx, allm, alls.astype(np.int64), n_old, opt, carry["shape"],
                                acc["seis_pairs"])
    keep = allT >= allT[-1] - max(abs(edges[0]), abs(edges[-1]))
    carry.update(T=allT[keep], x=allx[keep], main=allm[keep], s=alls[keep])
    # the exposures: of every mainshock whose window has been seen to its end, in time order
    for key, new in (("pending_T", T[main]), ("pending_x", x[main]), ("pending_s", rows.block[main])):
        carry[key] = np.concatenate([carry[key], new])
    seen = T[-1] - carry["pending_T"] >= edges[-1]
    if rows.last:
        _expose(acc, carry, seen, np.inf, opt)
        _expose(acc, carry, ~seen, T[-1], opt)      # windows cut by the task's end
        seen[:] = True
    else:
        _expose(acc, carry, seen, np.inf, opt)
    for key in ("pending_T", "pending_x", "pending_s"):
        carry[key] = carry[key][~seen]


def _cells(edges, lo, hi):
    """The bins lying wholly within [lo, hi) (bounds matched to edges within _EDGE of a bin's width)."""
    tol = _EDGE * np.min(np.diff(edges))
    return (edges[:-1] >= lo - tol) & (edges[1:] <= hi + tol)


@functools.lru_cache(maxsize=8)
def _regions(time_edges, distance_edges, near, ring, short, long):
    """{(time region, distance region): the flat indices of its cells} (edges as tuples: a cache key)."""
    time_edges, distance_edges = np.array(time_edges), np.array(distance_edges)
    times = {"before": (-short, 0.0), "after": (0.0, short), "earlier": (-long, -short)}
    distances = {"near": (0.0, near), "ring": (near, ring)}
    nd = len(distance_edges) - 1
    return {(t, d): (np.flatnonzero(_cells(time_edges, *times[t]))[:, None] * nd
                     + np.flatnonzero(_cells(distance_edges, *distances[d]))[None, :]).ravel()
            for t in times for d in distances}


def rate(u, cells):
    """Events per mainshock per block per T nu in the cells (flat indices) of a region."""
    counts = u["seis_pairs"][cells].sum()
    exposure = u["seis_exposure"][cells].sum()
    return counts / exposure if exposure > 0 else np.nan


def estimate(u, opt):
    cells = _regions(tuple(opt.seis_time_edges), tuple(opt.seis_distance_edges), opt.seis_near, opt.seis_ring,
                     opt.seis_short, opt.seis_long)
    with np.errstate(invalid="ignore", divide="ignore"):
        return [u.column(NAME, "n_gaps") / u.column(NAME, "block_span"),
                rate(u, cells["before", "near"]), rate(u, cells["after", "near"]),
                rate(u, cells["earlier", "near"]) / rate(u, cells["earlier", "ring"]),
                rate(u, cells["before", "near"]) / rate(u, cells["before", "ring"])]


def drawn(opt):
    """The cells of the map that the numbers read (a resample sums no other)."""
    cells = np.unique(np.concatenate(list(_regions(tuple(opt.seis_time_edges), tuple(opt.seis_distance_edges),
                                                   opt.seis_near, opt.seis_ring, opt.seis_short,
                                                   opt.seis_long).values())))
    return {"seis_pairs": cells, "seis_exposure": cells}


def rate_map(units, opt, rng):
    """The map of a point: its summed counts over its summed exposures, (time bins, distance bins)."""
    nt, nd = len(opt.seis_time_edges) - 1, len(opt.seis_distance_edges) - 1
    counts = units["seis_pairs"].sum(axis=0).reshape(nt, nd).astype(float)
    exposure = units["seis_exposure"].sum(axis=0).reshape(nt, nd)
    with np.errstate(invalid="ignore", divide="ignore"):
        return {"seismicity_rate": np.where(exposure > 0, counts / exposure, np.nan)}


def report_header(s):
    """The regions of the numbers, once for the summary."""
    a = s["attrs"]
    return [f"seismicity around mainshocks (mu >= mu_c): near = distance < {a['seis_near']:g} blocks, ring = up to "
            f"{a['seis_ring']:g}; just before/after = {a['seis_short']:g} T*nu, some time before = from "
            f"-{a['seis_long']:g}; rates per mainshock per block per T*nu"]


def map_table(s):
    """The maps, long format: one row per point, time bin and distance bin (ExportTable.build; no rows for a
    summary before format 5)."""
    columns = {
        "point": ("index", "parameter point (row of numbers.csv)"),
        "time_lo": ("model length", "lower edge of the time bin: T nu from the mainshock's onset, negative before it"),
        "time_hi": ("model length", "upper edge of the time bin (bins are half-open)"),
        "distance_lo": ("blocks", "lower edge of the distance bin: blocks from the mainshock's epicenter"),
        "distance_hi": ("blocks", "upper edge of the distance bin (bins are half-open)"),
        "rate": (RATE, "events per mainshock per block per unit T nu in the cell (NaN where nothing was exposed); the "
                       "background rate is in numbers.csv"),
    }
    values = {name: np.zeros(0) for name in columns}
    if holds(s, STATISTIC):
        rate, te, de = s["points/seismicity_rate"], s["bins/seis_time"], s["bins/seis_distance"]
        point, j, k = (a.ravel() for a in np.meshgrid(np.arange(len(rate)), np.arange(len(te) - 1),
                                                       np.arange(len(de) - 1), indexing="ij"))
        values = {"point": point, "time_lo": te[j], "time_hi": te[j + 1], "distance_lo": de[k],
                  "distance_hi": de[k + 1], "rate": rate[point, j, k]}
    values["point"] = values["point"].astype(np.int64)
    return columns, values


DECADES = 2   # the colour scale of the maps: rate / background from 10^-2 to 10^2


def figure_size(n):
    from ..drawing import grid
    rows, cols = grid(n)
    return 5.2 * cols + 1.2, 4.2 * rows + 0.8


def draw(summaries, fig, keys, labels, names, title):
    """One map per point (the grid of the recurrence panels): log10 of the rate at (distance, time) over the
    point's background rate, white where nothing was exposed; the numbers' regions outlined (near and ring,
    just before and after, some time before)."""
    from ..drawing import FONT, grid
    from ..figure_labels import points_of
    from ..report import count_text
    from ..summary import SummaryError
    points = [(s, i, label) for (s, i), label in zip(points_of(summaries), labels) if holds(s, STATISTIC)]
    if not points:
        raise SummaryError(f"{', '.join(map(str, names))}: no seismicity around large events (a summary before "
                           "format 5 did not reduce it: reduce its catalogs again)")
    fig.subplots_adjust(left=0.09, right=0.86, bottom=(0.55 + 0.3) / fig.get_figheight(),
                        top=1 - 1.1 / fig.get_figheight(), hspace=0.55, wspace=0.3)
    rows, cols = grid(len(points))
    mesh = None
    for k, (s, i, label) in enumerate(points):
        ax = fig.add_subplot(rows, cols, k + 1)
        background = s["points/numbers/background_rate"][i][0]
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = np.log10(s["points/seismicity_rate"][i] / background)
        relative = np.where(np.isfinite(relative), relative, np.where(relative == -np.inf, -DECADES, np.nan))
        mesh = ax.pcolormesh(s["bins/seis_distance"], s["bins/seis_time"], np.ma.masked_invalid(relative),
                             cmap="RdBu_r", vmin=-DECADES, vmax=DECADES, shading="flat")
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
    fig.suptitle(title, fontsize=FONT + 1, wrap=True)


RATE = "1/(block model length)"   # events per mainshock per block per unit T nu
STATISTIC = Statistic(
    NAME, 60,
    tables=(Table("seis_pairs", "count", "events (any size) at (time from a mainshock's onset, distance from its "
                                         "epicenter), per task and stretch of the mainshock",
                  bins=("seis_time", "seis_distance")),
            Table("seis_exposure", "block model length", "the mainshocks' exposure of each cell: the T nu of its "
                                                         "time bin within the task's span times the chain's blocks "
                                                         "in its distance bin", bins=("seis_time", "seis_distance"),
                  weights=True),
            Table(NAME, "count or sum", "mainshocks, and the events and block x T nu of the background",
                  columns=("n_main", "n_gaps", "block_span"))),
    numbers=(Number("background_rate", RATE, "inertial events per block per unit T nu over all the blocks and "
                                             "task (the events after the task's first over N M blocks times its span)",
                    "background rate"),
             Number("foreshock_rate", RATE, "events per mainshock per block per T nu at distance < seis_near from "
                                            "its epicenter in [-seis_short, 0) before its onset", "foreshock rate"),
             Number("aftershock_rate", RATE, "the same in [0, seis_short) after its onset (the mainshock left out)",
                    "aftershock rate"),
             Number("quiescence_ratio", "1", "rate at distance < seis_near over the rate at seis_near <= distance < "
                                             "seis_ring, both in [-seis_long, -seis_short) (< 1: quiet epicenter, "
                                             "active ring)", "quiescence ratio"),
             Number("doughnut_ratio", "1", "the same ratio just before the onset, in [-seis_short, 0)",
                    "doughnut ratio")),
    feed=feed, estimate=estimate, extra=rate_map, drawn=drawn, uses_options=("mu_c",), report_header=report_header,
    figures=(Figure("seismicity", "the rate of events around mainshocks by distance and time, one map per point",
                    figure_size, draw, bands=False),),
    exports=(ExportTable("seismicity", "one row per point, time bin and distance bin of the seismicity around its "
                                       "mainshocks", map_table),),
    # the defaults: for the aging law at b = 20, N = 800 (inter-event times of about 37 T nu, large events
    # recurring after T nu ~ 530)
    options=(Option("seis_time_bins", "bins", "-1000:1000:40", "model length",
                    "bins lo:hi:n of the time T*nu from a mainshock's onset, negative before it, of the seismicity "
                    "around mainshocks (mu >= mu_c; a negative lo after '=')"),
             Option("seis_distance_bins", "bins", "0:40:20", "blocks",
                    "bins lo:hi:n of the distance from a mainshock's epicenter, blocks"),
             Option("seis_near", "number", 2.0, "blocks", "its epicentral neighbourhood: distance < this",
                    0.0, 1e9),
             Option("seis_ring", "number", 10.0, "blocks", "its ring: from --seis-near to this", 0.0, 1e9),
             Option("seis_short", "number", 50.0, "model length",
                    "its 'just before' and 'just after' the onset, T*nu", 0.0, 1e300),
             Option("seis_long", "number", 500.0, "model length",
                    "its 'some time before': from -this to --seis-short, T*nu", 0.0, 1e300)),
    extra_datasets={"seismicity_rate": (RATE, "(points, seis_time bins, seis_distance bins)",
                                        "events per mainshock per block per unit T nu at (time from the mainshock's "
                                        "onset, distance from its epicenter); NaN where nothing was exposed")})
