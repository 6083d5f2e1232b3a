"""Slow slip beside the mainshocks (Kawamura, Yamamoto & Ueda, 2018, arXiv:1805.07237: main shocks, precursory
nucleation, afterslip and silent earthquakes in one framework), each kind defined from the catalog's rows. The
definitions are this code's (docs/successors.md):

- a mainshock: an inertial event with mu >= mu_c;
- its precursory creep: a creep episode it took over (/events/ending 2: the episode ends at the event's onset,
  within the rounding of the time) whose blocks first - 1 .. last + 1 hold its epicenter: the event grew out of
  that episode's creep (the epicenter of a hand-over is a block of the cluster, or the resting neighbour whose
  joining made the cluster too soft to creep);
- its afterslip: a creep episode that begins at most afterslip_window (T nu, the loader's displacement) after the
  mainshock's end (onset + duration) and whose blocks meet the mainshock's rupture zone or its two neighbours
  (first - 1 .. last + 1): the blocks an event hands back to creep begin such an episode at its end, and blocks it
  loaded past their threshold begin one soon after. An episode that could follow two mainshocks follows the later;
- a silent earthquake: a creep episode whose blocks all stopped by themselves (/events/ending 1: it never became
  an inertial event) and whose slip is a mainshock's, mu >= mu_c.

Stable sliding, the plate's motion taken up by creep alone, is the creep statistic's aseismic fraction near 1
with no mainshock. The numbers: mainshocks, the share of them with precursory creep and with afterslip, the
afterslip's slip over the slip of the mainshocks it follows, silent earthquakes and their share of the large
slips (silent earthquakes over silent earthquakes and mainshocks).

An episode's row comes when it ends, after the rows of the events during it, so the task's mainshocks are kept
from chunk to chunk (their onset, end, zone, slip, stretch and what has been counted of them: `acc.carry`); each
count is added once, when the episode that makes it is read, whatever the chunks.

A chain's statistic: a creep episode's and an event's blocks are intervals there (first..last), so "its blocks
hold the epicenter" and "meets the zone or its two neighbours" are exact. On a plane they are areas of which the
catalog keeps the extents along and across only, whose box also holds blocks of neither: a plane's points have no
numbers here (statistics.refusal).
"""
import numpy as np

from ensemble.store import schema

from . import Figure, Number, Option, Statistic, Table

NAME = "slow_slip"
COLUMNS = ("n_main", "n_precursor", "n_after", "sum_main_slip_after", "sum_afterslip", "n_silent")
_KEPT = ("onset", "end", "lo", "hi", "epicenter", "slip", "block", "precursor", "after")


def _spacing(t):
    """The rounding of a catalog time (the kernel's two-float clock stored as one float)."""
    return 8.0 * np.spacing(np.abs(t))


def _keep(carry, ev, block, main):
    """Append this chunk's mainshocks to the task's."""
    new = {"onset": ev["t"][main], "end": ev["t"][main] + ev["duration"][main], "lo": ev["first"][main] - 1,
           "hi": ev["last"][main] + 1, "epicenter": ev["epicenter"][main], "slip": ev["slip"][main],
           "block": block[main], "precursor": np.zeros(int(main.sum()), bool), "after": np.zeros(int(main.sum()), bool)}
    for key in _KEPT:
        carry[key] = np.concatenate([carry[key], new[key]]) if key in carry else new[key]


def feed(acc, rows):
    carry = acc.carry.setdefault(NAME, {})
    if rows.ev is not None:
        main = rows.ev["mu"] >= rows.opt.mu_c
        acc.add(NAME, "n_main", rows.block[main], 1)
        _keep(carry, rows.ev, rows.block, main)
    if rows.creep_block is None:
        return
    part, creep, block = rows.part, rows.creep, rows.creep_block
    mu, ending = part["mu"][creep], part["ending"][creep]
    silent = (ending == schema.ENDING_STOPPED) & (mu >= rows.opt.mu_c)
    acc.add(NAME, "n_silent", block[silent], 1)
    if not carry or not len(carry["onset"]):
        return
    start, first, last, slip = part["t"][creep], part["first"][creep], part["last"][creep], part["slip"][creep]
    end = start + part["duration"][creep]
    # precursory creep: the mainshock whose onset is the taken-over episode's end, its epicenter among its blocks
    taken = np.flatnonzero(ending == schema.ENDING_TAKEN_OVER)
    j = np.searchsorted(carry["onset"], end[taken] + _spacing(end[taken]), side="right") - 1
    ok = j >= 0
    taken, j = taken[ok], j[ok]
    ok = ((np.abs(carry["onset"][j] - end[taken]) <= _spacing(end[taken]))
          & (first[taken] - 1 <= carry["epicenter"][j]) & (carry["epicenter"][j] <= last[taken] + 1))
    _flag(acc, carry, "precursor", "n_precursor", j[ok])
    # afterslip: the last mainshock ending at or before the episode's start, within the window, next to its zone
    j = np.searchsorted(carry["end"], start + _spacing(start), side="right") - 1
    k = np.flatnonzero(j >= 0)
    j = j[k]
    near = (((start[k] - carry["end"][j]) * rows.nu <= rows.opt.afterslip_window)
            & (first[k] <= carry["hi"][j]) & (carry["lo"][j] <= last[k]))
    acc.add(NAME, "sum_afterslip", carry["block"][j[near]], slip[k[near]])
    fresh = _flag(acc, carry, "after", "n_after", j[near])
    acc.add(NAME, "sum_main_slip_after", carry["block"][fresh], carry["slip"][fresh])


def _flag(acc, carry, flag, column, m):
    """Count the mainshocks m (in the order of their first appearance: the episodes' order, whatever the chunks)
    not yet flagged; returns them."""
    m = np.asarray(m, dtype=np.int64)
    _, first = np.unique(m, return_index=True)
    fresh = m[np.sort(first)]
    fresh = fresh[~carry[flag][fresh]]
    carry[flag][fresh] = True
    acc.add(NAME, column, carry["block"][fresh], 1)
    return fresh


def estimate(u, opt):
    c = {name: u.column(NAME, name) for name in COLUMNS}
    with np.errstate(invalid="ignore", divide="ignore"):
        return [c["n_main"], c["n_precursor"] / c["n_main"], c["n_after"] / c["n_main"],
                c["sum_afterslip"] / c["sum_main_slip_after"], c["n_silent"],
                c["n_silent"] / (c["n_silent"] + c["n_main"])]


# the map's panels: (number shown by colour, its label, the number written under it, how it is written)
PANELS = (("aseismic_fraction", "aseismic slip fraction (1: stable sliding)", "n_main", "{:.0f} mainshocks"),
          ("precursor_share", "mainshocks with precursory creep", "n_main", "of {:.0f}"),
          ("afterslip_share", "mainshocks with afterslip", "afterslip_ratio", "slip ratio {:.2g}"),
          ("silent_share", "silent share of the large slips", "n_silent", "{:.0f} silent"))


def describe_map(summaries):
    """The title's words: the parameters every point shares (what was run), the events behind the points, mu_c and
    the afterslip window, and what a cell says."""
    from ..report import size_text
    shared = []
    for key in ("N", "l", "nu", "c"):
        values = {float(v) for s in summaries for v in s[f"points/{key}"]}
        if len(values) == 1:
            shared.append(f"{key} = {values.pop():g}")
    sizes = " / ".join(dict.fromkeys(size_text(s) for s in summaries))
    mu_c = " / ".join(dict.fromkeys(f"{s['attrs']['mu_c']:g}" for s in summaries))
    window = " / ".join(dict.fromkeys(f"{s['attrs'].get('afterslip_window', np.nan):g}" for s in summaries))
    return (f"{', '.join(shared)}; {sizes}, mainshocks mu >= {mu_c}, afterslip window {window} T nu; each cell: "
            "the number [its interval] and the count behind it")


def map_size(n):
    return 11, 8.6


def draw_map(summaries, fig, keys, labels, names, title):
    """The regime map: one panel per kind of slip over the grid of the two varying parameters (a and b if both
    vary), each cell coloured by its share and labelled with it, its interval and the count behind it; a cell
    without the number (no mainshock, or a summary before the statistic) is left blank."""
    from matplotlib import colormaps

    from ..drawing import FONT, layout
    from ..figure_labels import points_of
    from ..summary import SummaryError
    if not 1 <= len(keys) <= 2:
        raise SummaryError(f"{', '.join(map(str, names))}: the slow-slip map needs one or two varying parameters, "
                           f"not {len(keys)} ({', '.join(keys) or 'none'})")
    x_key, y_key = (("a", "b") if set(keys) == {"a", "b"} else (keys[0], keys[1] if len(keys) == 2 else None))
    points = points_of(summaries)
    xs = sorted({float(s[f"points/{x_key}"][i]) for s, i in points})
    ys = sorted({float(s[f"points/{y_key}"][i]) for s, i in points}) if y_key else [0.0]
    cmap = colormaps["viridis"]
    for ax, (name, label, under, fmt) in zip(fig.subplots(2, 2).flat, PANELS):
        grid = np.full((len(ys), len(xs)), np.nan)
        for s, i in points:
            if f"points/numbers/{name}" not in s:
                continue
            x = xs.index(float(s[f"points/{x_key}"][i]))
            y = ys.index(float(s[f"points/{y_key}"][i])) if y_key else 0
            est, lo, hi = s[f"points/numbers/{name}"][i]
            grid[y, x] = est
            text = "-" if np.isnan(est) else f"{est:.2g}\n[{lo:.2g}, {hi:.2g}]"
            if f"points/numbers/{under}" in s and np.isfinite(s[f"points/numbers/{under}"][i][0]):
                text += "\n" + fmt.format(s[f"points/numbers/{under}"][i][0])
            ax.text(x, y, text, ha="center", va="center", fontsize=FONT,
                    color="white" if np.isfinite(est) and est < 0.5 else "black")
        mesh = ax.pcolormesh(np.arange(len(xs) + 1) - 0.5, np.arange(len(ys) + 1) - 0.5, np.ma.masked_invalid(grid),
                             cmap=cmap, vmin=0.0, vmax=1.0)
        fig.colorbar(mesh, ax=ax, fraction=0.05)
        ax.set_xticks(range(len(xs)), [f"{v:g}" for v in xs])
        ax.set_yticks(range(len(ys)), [f"{v:g}" for v in ys] if y_key else [""])
        ax.set_xlabel(x_key)
        if y_key:
            ax.set_ylabel(y_key)
        ax.set_title(label, fontsize=FONT + 1)
    layout(fig, title, 0.1)


STATISTIC = Statistic(
    NAME, 96,
    tables=(Table(NAME, "count or sum", "mainshocks (mu >= mu_c), those with precursory creep and with afterslip, the "
                                        "slip of the latter and of their afterslip, and silent earthquakes, per task "
                                        "and stretch (of the mainshock; of the inertial events before a silent one)",
                  columns=COLUMNS),),
    numbers=(Number("n_main", "count", "mainshocks: inertial events with mu >= mu_c", "mainshocks"),
             Number("precursor_share", "1", "share of the mainshocks that took over a creep episode at or next to "
                                            "their epicenter (precursory creep)", "with precursory creep"),
             Number("afterslip_share", "1", "share of the mainshocks followed by afterslip: a creep episode beginning "
                                            "within afterslip_window of their end, next to their rupture zone",
                    "with afterslip"),
             Number("afterslip_ratio", "1", "slip of the afterslip episodes over the slip of the mainshocks they "
                                            "follow", "afterslip / mainshock slip"),
             Number("n_silent", "count", "silent earthquakes: creep episodes that stopped by themselves (never "
                                         "inertial) with mu >= mu_c", "silent earthquakes"),
             Number("silent_share", "1", "silent earthquakes over silent earthquakes and mainshocks (the large slips "
                                         "that were silent)", "silent share")),
    feed=feed, estimate=estimate, uses_tables=(), uses_options=("mu_c",),
    figures=(Figure("slow_slip", "the regime map of slow slip: the aseismic fraction, the shares of mainshocks with "
                                 "precursory creep and with afterslip, and the silent share, over the grid of the two "
                                 "varying parameters", map_size, draw_map, describe=describe_map),),
    options=(Option("afterslip_window", "number", 0.01, "model length",
                    "afterslip: a creep episode beginning at most this long (T nu) after a mainshock's end", 0.0,
                    1e9),),
    # on a plane a creeping cluster and a rupture zone are areas; the catalog keeps their extents only, whose box
    # holds blocks of neither, so "next to" could not be told
    geometries=("chain",), why_not="its precursors and afterslip are intervals of blocks next to each other on a chain")
