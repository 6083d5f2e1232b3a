"""Did this run reproduce the paper? The claims of Ohmura & Kawamura (EPL 77, 69001, 2007) beside
the numbers of one or more summaries (`python -m analysis paper SUMMARY [SUMMARY ...]`).

Each claim (CLAIMS) names the points it needs: which parameter values (`where`) and which parameter
it runs over (`vary`, with at least `least` values of it). It takes them from the one summary that
has the most values of `vary` among its points that match (the first of equals), so that given
the five panels' summaries in the order of docs/paper.md each claim reads its own panel; a claim no
summary allows says what it needs. Numbers the report prints (fraction of large events, GR b, KS
distance, recurrence peaks) are the summary's, with its intervals; the shape of R(mu) (the
large-magnitude peak, the dip below it, their ratio, the spread of a flat R(mu)) is computed here
from the per-stretch histograms, with percentile intervals from RESAMPLES resamples of the same
units (stats.bootstrap, seed 0). A number that cannot be computed says why instead of printing nan.

The output is labelled "full size" when every point rests on at least PAPER_EVENTS events (the
paper's one trajectory per point), else "reduced"; a run that discarded fewer events than the
longest transient measured is warned about. A reduced run's points that the committed full-size
panels (docs/paper) also have are set beside them, number by number: is the full size's value
inside this run's interval?
"""
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ensemble.config import MEASURED_TRANSIENT_PER_BLOCK, TRANSIENT_PER_BLOCK

from . import stats, summary
from .geometry import CHAIN
from .reduce import PARAMS
from .report import LABELS, count_text, events_per_point, level_text, partial_text, point_label, size_text

PAPER_EVENTS = 200_000      # events the paper recorded per point (one trajectory, N = 800) ...
PAPER_TRANSIENT = 10_000    # ... after discarding these
PAPER_LAW = "aging"         # the paper's friction law: a point of another law is not the paper's model
# the committed full-size panels (docs/paper.md), in the order whose claims read their own panel;
# a reduced run's numbers are set beside theirs
FULL_SIZE = Path(__file__).resolve().parents[1] / "docs" / "paper"
PANELS = ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b")
# numbers whose value does not depend on the trajectory's length (not mean T nu: a short trajectory
# never sees the long recurrence times, so its mean is lower; docs/paper.md)
COMPARED = ("fraction_large", "gr_b", "ks_gr")

RESAMPLES = 1000
PEAK_FROM = 3.5            # the large-magnitude peak: the maximum of R(mu) for mu >= PEAK_FROM
DIP_FROM = 2.5             # the dip: the minimum of R(mu) between DIP_FROM and the peak
FLAT = (3.0, 5.5)          # a flat R(mu): max / min of R over this range (above the few-block events)
SHAPES = ("peak_mu", "peak_r", "dip_mu", "dip_r", "peak_over_dip", "flat_spread")


def fmt(v, digits=3):
    return f"{v:.{digits}g}"


def with_interval(triple, digits=3):
    """"est [lo, hi]"; an estimate that is not finite, or no interval, said in words."""
    est, lo, hi = triple[:3]
    if not np.isfinite(est):
        return "not computable from these events"
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return f"{fmt(est, digits)} (no interval: too few resampling units)"
    return f"{fmt(est, digits)} [{fmt(lo, digits)}, {fmt(hi, digits)}]"


def number(s, i, name, digits=3):
    return with_interval(s[f"points/numbers/{name}"][i], digits)


def _shape(row, edges, c):
    """SHAPES of one histogram row (bin counts, then the events in and out of range)."""
    r = stats.density(row[:-1], edges, row[-1])
    big = np.flatnonzero(c >= PEAK_FROM)
    if not big.size or not np.isfinite(r).all():      # bins below the peak's range, or no events
        return np.full(len(SHAPES), np.nan)
    k = big[np.argmax(r[big])]
    below = np.flatnonzero((c >= DIP_FROM) & (c <= c[k]))
    j = below[np.argmin(r[below])]
    flat = np.flatnonzero((c >= FLAT[0]) & (c <= FLAT[1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.array([c[k], r[k], c[j], r[j], r[k] / r[j], r[flat].max() / r[flat].min()])


def shape_statistics(s, i, level=None, merge=1):
    """R(mu) shape numbers of point i with bootstrap intervals over its units (the summary's:
    seeds or a region's faults, or the stretches of every trajectory):
    {name: (estimate, lo, hi, share of resamples where it is infinite)}; a ratio over an empty
    bin is infinite. merge: read R(mu) in bins of that many of the summary's (a peak and a dip
    read from narrow bins are their noise's extremes, and the ratio's resamples lie above it)."""
    level = s["attrs"]["level"] if level is None else level
    edges, counts, events = summary.point_units(s, i, merge)
    c = stats.centers(edges)
    # the summary's own units: seeds (a region's faults), else every stretch
    if s["points/method"][i] in ("seeds", "faults"):
        counts, events = counts.sum(axis=1, keepdims=True), events.sum(axis=1, keepdims=True)
    rows = np.concatenate([counts.reshape(-1, len(c)), events.reshape(-1, 1)], axis=1)
    est = _shape(rows.sum(axis=0), edges, c)
    samples = stats.bootstrap(rows, lambda row: _shape(row, edges, c), RESAMPLES, np.random.default_rng(0))
    lo, hi = stats.percentile_interval(samples, level)
    infinite = np.mean(np.isinf(samples), axis=0)
    return {k: (est[n], lo[n], hi[n], infinite[n]) for n, k in enumerate(SHAPES)}


def ratio(quad, empty):
    """A ratio with its interval; over an empty bin (`empty` names it) infinite, said in words."""
    est, lo, hi, infinite = quad
    if np.isnan(est):
        return with_interval(quad)
    if not np.isfinite(est):
        return f"unbounded ({empty} holds no events: more events needed)"
    if not np.isfinite(hi):
        return (f"{fmt(est)} [{fmt(lo)}, unbounded: {empty} is empty in {100 * infinite:.0f}% of the "
                "resamples]")
    return with_interval(quad)


def peaks(s, i):
    rows = s["points/peaks"][i]
    rows = rows[np.isfinite(rows[:, 0])]
    return "; ".join(with_interval(r, 4) for r in sorted(rows, key=lambda r: r[0])) or "no significant peak"


def listing(s, rows, value, label):
    """'v1, v2, ... (label = x1, x2, ...)' over the points `rows` of summary s; when other
    parameters differ between them too, each point is named in full."""
    keys = [k for k in PARAMS
            if len({float(s[f"points/{k}"][i]) for i in rows if np.isfinite(s[f"points/{k}"][i])}) > 1]
    if keys in ([], [label]):
        return (", ".join(value(i) for i in rows) + f" ({label} = "
                + ", ".join(f"{s[f'points/{label}'][i]:g}" for i in rows) + ")")
    return ", ".join(f"{value(i)} ({point_label(s, i, keys)})" for i in rows)


def _peak_and_dip(s, rows):
    def one(i):
        sh = shape_statistics(s, i)
        return (f"peak at mu = {with_interval(sh['peak_mu'])}, "
                f"{ratio(sh['peak_over_dip'], 'the dip bin')} times R at the dip below it "
                f"(mu = {with_interval(sh['dip_mu'])})")
    return "; ".join(one(i) + (f" ({point_label(s, i)})" if len(rows) > 1 else "") for i in rows)


def _flat_spread(s):
    """Point i -> its max / min of R(mu) over FLAT, as text (a column of `listing`)."""
    return lambda i: ratio(shape_statistics(s, i)["flat_spread"], "the lowest bin")


def _flat(s, rows):
    spread = _flat_spread(s)
    text = (f"max / min of R over {FLAT[0]:g} <= mu <= {FLAT[1]:g}: " + listing(s, rows, spread, "b"))
    twenty = [i for i in range(len(s["points/b"])) if s["points/b"][i] == 20.0]
    if len(twenty) == 1:
        text += f"; {spread(twenty[0])} for b = 20"
    return text


def _ks(s, rows):
    return (f"KS distance of R(mu) to the fitted power law (GR b above mu = {s['attrs']['b_cut']:g}): "
            + listing(s, rows, lambda i: number(s, i, "ks_gr"), "b"))


def _large(vary):
    def text(s, rows):
        return (f"fraction of events with mu >= {s['attrs']['mu_c']:g}: "
                + listing(s, rows, lambda i: number(s, i, "fraction_large"), vary))
    return text


WORDS = {2: "two", 3: "three", 4: "four", 5: "five"}


def _c(s, rows):
    text = _large("c")(s, rows) + "; c drops out of the equations exactly (a shift of u)"
    if all(len({float(s[f"points/{k}"][i]) for i in rows}) == 1 for k in ("N", "l", "nu", "a", "b")):
        text += f": one model, {WORDS.get(len(rows), len(rows))} trajectories"
    return text


def _recurrence(s, rows):
    return "T nu at the peaks: " + listing(s, rows, lambda i: peaks(s, i), "N")


def _large_b(s, rows):
    spread = _flat_spread(s)
    return (_large("b")(s, rows) + "; KS distance to GR: " + listing(s, rows, lambda i: number(s, i, "ks_gr"), "b")
            + f"; max / min of R over {FLAT[0]:g}..{FLAT[1]:g}: " + listing(s, rows, spread, "b"))


@dataclass(frozen=True)
class Claim:
    statement: str                 # the paper's, as we read its text and figures
    where: dict                    # parameter -> the values a point may have
    vary: str                      # the parameter the claim runs over
    least: int                     # values of `vary` it needs
    numbers: Callable              # (summary, its points) -> the numbers that test it, as text


CLAIMS = (
    Claim("b = 20: R(mu) has a characteristic peak at large magnitude", {"b": (20.0,)}, "b", 1, _peak_and_dip),
    Claim("b = 30..50: a flatter R(mu), no deep dip", {"b": (30.0, 40.0, 50.0)}, "b", 1, _flat),
    Claim("R(mu) is not a Gutenberg-Richter power law", {"b": (20.0, 30.0, 40.0, 50.0)}, "b", 1, _ks),
    Claim("little dependence on a (b = 50)", {"b": (50.0,)}, "a", 2, _large("a")),
    Claim("little dependence on c (b = 20)", {"b": (20.0,)}, "c", 2, _c),
    Claim("b = 20: a sharp recurrence peak near T nu ~ 500", {"b": (20.0,)}, "N", 1, _recurrence),
    Claim("b = 40: two recurrence peaks", {"b": (40.0,)}, "N", 1, _recurrence),
    Claim("larger b (60, 80, 100): a preliminary study", {"b": (60.0, 80.0, 100.0)}, "b", 1, _large_b),
)


def _matching(s, claim):
    """The points of `s` that test `claim` (the paper's law, on a chain: a plane's points never do) and how many
    values of claim.vary they hold."""
    laws, chains = summary.point_laws(s), summary.point_geometries(s) == CHAIN
    rows = [i for i in range(len(s["points/N"]))
            if laws[i] == PAPER_LAW and chains[i]
            and all(s[f"points/{k}"][i] in values for k, values in claim.where.items())]
    vary = (claim.vary,) if isinstance(claim.vary, str) else claim.vary
    return rows, len({tuple(float(s[f"points/{k}"][i]) for k in vary) for i in rows})


def points_for(claim, summaries):
    """(summary, its points) that test `claim`: the summary with the most values of claim.vary (one parameter, or
    a tuple of them, distinct together) among its matching points (the first of equals), or None if none has
    claim.least. A claim with `needs` (numbers by name) reads only a summary that holds them all."""
    best = None
    for s in summaries:
        if not all(f"points/numbers/{n}" in s for n in getattr(claim, "needs", ())):
            continue
        rows, values = _matching(s, claim)
        if values >= claim.least and (best is None or values > best[2]):
            best = (s, rows, values)
    return None if best is None else best[:2]


def _needs(claim):
    where = " or ".join(f"{v:g}" for v in next(iter(claim.where.values())))
    key = next(iter(claim.where))
    more = f" with {WORDS.get(claim.least, claim.least)} or more values of {claim.vary}" if claim.least > 1 else ""
    return f"not computed: needs points with {key} = {where}{more}"


def is_full_size(summaries):
    return all((events_per_point(s) >= PAPER_EVENTS).all() for s in summaries)


def claims_table(summaries):
    """The paper's claims and this run's numbers as a Markdown table (the README's, on the five
    full-size panels)."""
    level = " / ".join(dict.fromkeys(level_text(s["attrs"]["level"]) for s in summaries))
    size = "full size" if is_full_size(summaries) else "reduced"
    out = [f"| the paper (Ohmura & Kawamura 2007) | {size}, this code ({level} intervals) |", "|---|---|"]
    for claim in CLAIMS:
        found = points_for(claim, summaries)
        out.append(f"| {claim.statement} | {claim.numbers(*found) if found else _needs(claim)} |")
    return "\n".join(out)


def transients(s, name):
    """Warnings (and notes) on the transients the catalogs of summary s discarded, one line each."""
    lines = []
    configs = [tomllib.loads(c) for c in s["attrs"]["configs"]]
    for k, path in enumerate(s["attrs"]["catalogs"]):
        tasks = np.flatnonzero(s["tasks/catalog"] == k)
        if not len(tasks):
            continue
        transient = configs[k].get("run", {}).get("transient")
        if transient is None:      # a config from before run.transient was resolved and stored
            lines.append(f"note: {path}: its stored config does not say how many events it discarded")
            continue
        transient = int(transient)
        blocks = s["tasks/N"][tasks] * (s["tasks/M"][tasks] if "tasks/M" in s else 1)    # N M on a plane
        n_blocks = int(blocks.max())
        at = f"N = {n_blocks}" if "tasks/M" not in s else f"{n_blocks} blocks"
        measured = MEASURED_TRANSIENT_PER_BLOCK * n_blocks
        if transient < measured:
            lines.append(f"warning: {path}: run.transient = {transient} events at {at}, shorter than "
                         f"the longest transient measured ({measured:g} events, {MEASURED_TRANSIENT_PER_BLOCK:g} per "
                         "block: docs/benchmarks.md): its statistics include the random start")
        elif transient < TRANSIENT_PER_BLOCK * n_blocks:
            lines.append(f"note: {path}: run.transient = {transient} events at {at}, no shorter than the "
                         f"longest transient measured ({measured:g}) but without the default's margin "
                         f"({TRANSIENT_PER_BLOCK} N = {TRANSIENT_PER_BLOCK * n_blocks} events, "
                         f"{TRANSIENT_PER_BLOCK / MEASURED_TRANSIENT_PER_BLOCK:g}x the measured)")
    return lines


def size_lines(summaries, names):
    """The full size / reduced statement, one line per summary."""
    lines = []
    for s, name in zip(summaries, names):
        if (events_per_point(s) >= PAPER_EVENTS).all():
            lines.append(f"{name}: full size, {size_text(s)} (the paper: {count_text(PAPER_EVENTS)} per point "
                         f"after {count_text(PAPER_TRANSIENT)} discarded)")
        else:
            lines.append(f"{name}: reduced, {size_text(s)} (the paper: {count_text(PAPER_EVENTS)} per point after "
                         f"{count_text(PAPER_TRANSIENT)} discarded); the full size's numbers: README.md, "
                         "docs/paper/tables.md")
    return lines


def full_size_panels(directory=FULL_SIZE):
    """[(path, summary)] of the committed full-size panels ([] where they are not: outside a
    source checkout)."""
    paths = [Path(directory) / f"{name}.summary.h5" for name in PANELS]
    return [(path, summary.read(path)) for path in paths if path.exists()]


def _short(path):
    """A summary's file name without .summary.h5."""
    return Path(str(path)).name.removesuffix(".h5").removesuffix(".summary")


def _same_point(s, i, r, j):
    return (summary.point_laws(s)[i] == summary.point_laws(r)[j]
            and all(np.array_equal(s[f"points/{k}"][i], r[f"points/{k}"][j], equal_nan=True) for k in PARAMS))


def other_models(summaries, names):
    """A line for each summary with points of another friction law than the paper's: not its model, so never set
    beside its claims nor judged against the full size."""
    lines = []
    for s, name in zip(summaries, names):
        laws = summary.point_laws(s)
        other = [str(law) for law in laws if law != PAPER_LAW]
        if other:
            kinds = ", ".join(f"{other.count(law)} of the {law} law" for law in dict.fromkeys(other))
            lines.append(f"not the paper's model: {name}: {kinds} of its {len(laws)} point(s) (the paper's law is "
                         f"the {PAPER_LAW} law): left out of the claims and of the comparison with the full size")
    return lines


def against_full_size(summaries, names, reference):
    """A Markdown table: for every point of a reduced summary that a full-size panel (`reference`,
    [(path, summary)], the first that has it) also has, with the same options, each of COMPARED
    with this run's interval, the full size's, and whether the full size's estimate lies inside
    this run's interval. "" when there is nothing to compare."""
    rows, inside = [], []
    options = ("mu_c", "window", "b_cut")
    for s, name in zip(summaries, names):
        if (events_per_point(s) >= PAPER_EVENTS).all():
            continue
        for i in range(len(s["points/N"])):
            found = [(path, r, j) for path, r in reference for j in range(len(r["points/N"]))
                     if _same_point(s, i, r, j) and all(s["attrs"][o] == r["attrs"][o] for o in options)]
            if not found:
                continue
            path, r, j = found[0]
            for key in COMPARED:
                est, lo, hi = s[f"points/numbers/{key}"][i]
                full = r[f"points/numbers/{key}"][j]
                verdict = "yes" if lo <= full[0] <= hi else "no" if np.isfinite([lo, hi]).all() else "-"
                inside.append(verdict)
                rows.append(f"| {point_label(s, i)} ({_short(name)}) | {LABELS[key]} | "
                            f"{with_interval((est, lo, hi))} | {with_interval(full)} ({_short(path)}) | "
                            f"{verdict} |")
    if not rows:
        return ""
    judged = [v for v in inside if v != "-"]
    return "\n".join(
        ["Against the full size (docs/paper; the same point and options): is the full size's value inside "
         "this run's interval?", "",
         "| point | number | this run | full size | inside |", "|---|---|---|---|---|", *rows, "",
         f"{judged.count('yes')} of {len(judged)} inside (about {level_text(summaries[0]['attrs']['level'])} "
         "expected if the runs differ only in length and the intervals are right; the KS intervals are "
         "about 1.6x too narrow: docs/paper.md)"])


def text(summaries, names, reference=None):
    """Everything `analysis paper` prints; reference: the full-size panels to compare a reduced
    run with (default: the committed ones, full_size_panels())."""
    lines = ["The paper's claims (Ohmura & Kawamura, EPL 77, 69001, 2007) beside this code's numbers", ""]
    lines += size_lines(summaries, names)
    for s, name in zip(summaries, names):
        if partial_text(s):
            lines.append(f"warning: {name}: {partial_text(s)}")
        lines += transients(s, name)
    lines += other_models(summaries, names)
    lines += ["", claims_table(summaries)]
    if not is_full_size(summaries):
        comparison = against_full_size(summaries, names, full_size_panels() if reference is None else reference)
        if comparison:
            lines += ["", comparison]
    return "\n".join(lines)
