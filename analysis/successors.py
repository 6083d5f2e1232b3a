"""What the seed paper's authors asked next, beside this code's numbers (`python -m analysis successors [SUMMARY
...]`, by default the committed summaries of docs/successors): the claims of the abstracts of Kawamura et al. 2017
(statistical properties), Ueda et al. 2015 (the nucleation process) and Kawamura, Yamamoto & Ueda 2018 (slow
slip), each with the numbers of the summaries that test it and their intervals, as `analysis paper` does for the
seed (analysis/paper.py). The papers' texts were not at hand: every definition behind a number is this code's,
written in its statistic's module (docs/successors.md).

A claim of the first two papers (PAPERS) reads the one summary with the most distinct values of the parameters it
runs over among its points that match (the first of equals: SUMMARIES is the committed ones' order), as the seed's
claims do, and only a summary that holds the numbers it needs (one reduced before their statistic does not). The
slow-slip claims read every point of every summary given that holds the slow-slip numbers: the paper's claim is
that varying a few parameters gives every kind. Numbers the summary holds are printed with its intervals; the few
computed here from its per-stretch tables (each class's share of large events, the widest zone's dependence on
magnitude) get percentile intervals from paper.RESAMPLES resamples of the same units, seed 0. The nucleation section
ends with a table of every point.
"""
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from . import stats, summary
from .geometry import CHAIN
from .paper import PAPER_LAW, RESAMPLES, WORDS, fmt, number, points_for, transients, with_interval
from .reduce import PARAMS
from .report import level_text, partial_text, point_label, size_text

COMMITTED = Path(__file__).resolve().parents[1] / "docs" / "successors"
# the committed summaries, the order in which claims of equal standing read them
SUMMARIES = ("ruptures", "continuum", "nucleation", "slow_slip_l3_nu1e-8", "slow_slip_l3_nu1e-4",
             "slow_slip_l12_nu1e-8", "slow_slip_l12_nu1e-4")


def committed(directory=COMMITTED):
    """The committed summaries' paths that exist ([] outside a source checkout)."""
    paths = [Path(directory) / f"{name}.summary.h5" for name in SUMMARIES]
    return [p for p in paths if p.exists()]


def stiffness(s, i):
    """A block's stiffness on the chain, 1 + 2 l^2: a block whose weakening b is below it creeps before it
    ruptures (the weak regime). On a plane of M rows the stiffest (interior) block's, 1 + 2 l^2 plus l_across^2 for
    each neighbour across strike (two where M >= 3; its edge rows have one)."""
    chain = 1.0 + 2.0 * s["points/l"][i] ** 2
    M = int(s["points/M"][i]) if "points/M" in s else 1
    return chain + min(M - 1, 2) * s["points/l_across"][i] ** 2 if M > 1 else chain


def _units(s, i, tables):
    """Point i's resampling units of the per-stretch tables `tables` side by side: (units, sum of their widths);
    the summary's seeds (or a region's faults) where it resamples those, else every stretch of every task."""
    tasks = np.flatnonzero(s["tasks/point"] == i)
    parts = [s[f"per_task/{t}"][tasks] for t in tables]
    if s["points/method"][i] in ("seeds", "faults"):
        parts = [p.sum(axis=1, keepdims=True) for p in parts]
    return np.concatenate([p.reshape(-1, p.shape[-1]) for p in parts], axis=1)


def resampled(s, i, tables, statistic):
    """(estimate, lo, hi) of `statistic` (of the summed row of `tables`) at point i, with a percentile interval over
    RESAMPLES resamples of its units (stats.bootstrap, seed 0)."""
    units = _units(s, i, tables)
    with np.errstate(invalid="ignore", divide="ignore"):
        est = statistic(units.sum(axis=0))
        samples = stats.bootstrap(units, statistic, RESAMPLES, np.random.default_rng(0))
    lo, hi = stats.percentile_interval(samples[:, None], s["attrs"]["level"])
    return est, lo[0], hi[0]


def large_share(s, i, table):
    """The share of a class's events (R(mu) of the class: `table`, mu_uni or mu_bi) with mu >= mu_c."""
    large = stats.centers(s["bins/mu"]) >= s["attrs"]["mu_c"]
    return resampled(s, i, [table], lambda row: row[large].sum() / row.sum())


def widest_zone_ratio(s, i):
    """L_c of the larger half of the large events over the smaller half's, as text with its interval: the
    magnitudes of the large events (mu >= mu_c) split at the middle of their range (from mu_c to the upper edge of
    the highest bin holding one); said in words where a half is empty."""
    edges, c = s["bins/mu"], stats.centers(s["bins/mu"])
    n = _units(s, i, ["nuc_n"]).sum(axis=0)
    large = c >= s["attrs"]["mu_c"]
    if not n[large].any():
        return "no large events"
    top = edges[1:][large & (n > 0)].max()
    upper = large & (c >= (s["attrs"]["mu_c"] + top) / 2)
    lower = large & ~upper
    if not n[lower].any():
        low = edges[:-1][large & (n > 0)].min()
        return f"not computable: its large events lie within mu = {low:.3g} to {top:.3g}, no range of sizes"
    k = len(c)

    def ratio(row):
        count, total = row[:k], row[k:]
        return (total[upper].sum() / count[upper].sum()) / (total[lower].sum() / count[lower].sum())
    return with_interval(resampled(s, i, ["nuc_n", "nuc_len"], ratio))


# -- Kawamura, Ueda, Kakui, Morimoto & Yamamoto 2017: statistical properties ----------------------------------

def per_point(s, rows, value):
    """value(i) of each point, 'N = 800: ...; N = 1600: ...' (labelled by the parameters that differ among them)."""
    keys = _varying(s, rows)
    if len(rows) == 1 or not keys:
        return "; ".join(value(i) for i in rows)
    return "; ".join(f"{point_label(s, i, keys)}: {value(i)}" for i in rows)


def _length(s, rows):
    a = s["attrs"]
    top = f"min({a['lr_max']}, N - 1)" if a["lr_max"] < 10 ** 9 else "N - 1"
    return (f"L_0 fitted on {a['lr_min']} <= L_r <= {top}: "
            + per_point(s, rows, lambda i: f"{number(s, i, 'L0', 4)} blocks "
                                           f"({int(s['points/numbers/n_L0'][i][0])} events)"))


def _classes(s, rows):
    a = s["attrs"]
    return (f"of the ruptures of at least {a['class_min']} blocks that reach neither end, the unilateral ones "
            f"(epicenter within {a['uni_edge']:g} of the zone's length from one of its ends), and of each class the "
            f"share whose epicenter lies within {a['window']} blocks of the rim of the previous large event's zone: "
            + per_point(s, rows, lambda i: f"unilateral {number(s, i, 'fraction_unilateral')}, at the rim "
                                           f"{number(s, i, 'uni_at_rim')} of them against {number(s, i, 'bi_at_rim')} "
                                           "of the bilateral"))


def _characteristic(s, rows):
    return (f"share of each class's events with mu >= {s['attrs']['mu_c']:g}: "
            + per_point(s, rows, lambda i: f"bilateral {with_interval(large_share(s, i, 'mu_bi'))}, unilateral "
                                           f"{with_interval(large_share(s, i, 'mu_uni'))}"))


def _slip(s, rows):
    return (f"over {s['attrs']['lr_min']} <= L_r <= N - 1, the mean slip per block and the mean stress drop, each "
            "with its upper half of the range over its lower half: "
            + per_point(s, rows, lambda i: f"slip {number(s, i, 'mean_slip_large', 4)}, "
                                           f"{number(s, i, 'slip_ratio', 4)}; drop "
                                           f"{number(s, i, 'mean_drop_large', 4)}, {number(s, i, 'drop_ratio', 4)}"))


def _correlations(s, rows):
    a = s["attrs"]
    return (f"per mainshock (mu >= {a['mu_c']:g}), per block and unit T nu, within {a['seis_near']:g} blocks of "
            f"its epicenter over {a['seis_short']:g} T nu before and after it, against the background; the "
            f"quiescence and doughnut ratios (near over the ring up to {a['seis_ring']:g} blocks, long and just "
            "before): " + per_point(s, rows, lambda i: f"foreshocks {number(s, i, 'foreshock_rate')}, aftershocks "
                                                       f"{number(s, i, 'aftershock_rate')}, background "
                                                       f"{number(s, i, 'background_rate')}, quiescence "
                                                       f"{number(s, i, 'quiescence_ratio')}, doughnut "
                                                       f"{number(s, i, 'doughnut_ratio')}"))


def _continuum(s, rows):
    def one(i):
        if not np.isfinite(s["points/numbers/L0"][i][0]):
            return f"not computable ({int(s['points/numbers/n_L0'][i][0])} events in the fit's range)"
        return f"{number(s, i, 'L0', 4)}, over l {with_interval(s['points/numbers/L0'][i] / s['points/l'][i])}"
    return f"L_0 fitted on {s['attrs']['lr_min']} <= L_r <= N - 1: " + per_point(s, rows, one)


# -- Ueda, Morimoto, Kakui, Yamamoto & Kawamura 2015: the nucleation process ----------------------------------

def _finite(s, rows, name):
    return [i for i in rows if np.isfinite(s[f"points/numbers/{name}"][i][0])]


def _span(values):
    """'1.2 to 3.4', or '1 at every point' where they are one value."""
    values = list(values)
    lo, hi = min(values), max(values)
    return f"{fmt(lo)} at every point" if fmt(lo) == fmt(hi) else f"{fmt(lo)} to {fmt(hi)}"


def _phases(s, rows):
    known = _finite(s, rows, "L_c")
    if not known:
        return "not computable: no point has large events"
    share = [s["points/numbers/spread_share"][i][0] for i in known]
    return (f"the large events whose sliding zone grows beyond the blocks sliding at its onset (the initial phase) "
            f"to its widest, L_c (the acceleration phase), before the rupture runs on: share {_span(share)} "
            f"({len(known)} points with large events; the phases' lengths and durations: the rows below and the table "
            "of every point)")


def _varying(s, rows):
    return [k for k in PARAMS
            if len({float(s[f"points/{k}"][i]) for i in rows if np.isfinite(s[f"points/{k}"][i])}) > 1]


def _label(s, rows, i):
    """Point i named by b, l and whatever else varies among `rows`."""
    return point_label(s, i, ["b", "l"] + [k for k in _varying(s, rows) if k not in ("b", "l")])


def _by(s, rows, name, per):
    """'l = 3: v, v, ... (b = 10, ...); l = 6: ...' of number `name` (estimates) at each value of `per`; each point
    named in full where parameters other than b and l vary too."""
    other = "b" if per == "l" else "l"
    if set(_varying(s, rows)) - {"b", "l"}:
        return per_point(s, rows, lambda i: fmt(s[f"points/numbers/{name}"][i][0]))
    parts = []
    for value in dict.fromkeys(float(s[f"points/{per}"][i]) for i in rows):
        at = sorted((i for i in rows if s[f"points/{per}"][i] == value), key=lambda i: s[f"points/{other}"][i])
        parts.append(f"{per} = {value:g}: " + ", ".join(fmt(s[f"points/numbers/{name}"][i][0]) for i in at)
                     + f" ({other} = " + ", ".join(f"{s[f'points/{other}'][i]:g}" for i in at) + ")")
    return "; ".join(parts)


def _lengths(s, rows):
    known = _finite(s, rows, "L_c")
    if not known:
        return "not computable: no point has large events"
    over_l = [s["points/numbers/L_c"][i][0] / s["points/l"][i] for i in known]
    return (f"L_c (widest zone, blocks): {_by(s, known, 'L_c', 'l')}; L_c / l from "
            f"{_span(over_l)}. L_sc (onset zone): {_by(s, known, 'L_sc', 'l')} (intervals: the table below)")


def _regimes(s, rows):
    known = _finite(s, rows, "L_sc")
    strong = [i for i in known if s["points/b"][i] > stiffness(s, i)]
    weak = [i for i in known if s["points/b"][i] < stiffness(s, i)]
    one = [i for i in strong if s["points/numbers/L_sc"][i][0] == 1.0]
    more = [i for i in weak if s["points/numbers/L_sc"][i][0] > 1.0]
    text = (f"the onset zone is one block (L_sc = 1) at {len(one)} of {len(strong)} points with b above the block "
            f"stiffness 1 + 2 l^2 (strong), a creeping cluster (L_sc > 1) at {len(more)} of {len(weak)} below it "
            "(weak)").replace("at 0 of 0 points", "at no point").replace("at 0 of 0 below", "at no point below")
    odd = [i for i in strong if i not in one] + [i for i in weak if i not in more]
    if odd:
        text += "; not so at " + "; ".join(_label(s, known, i) for i in odd)
    return text


def _size(s, rows):
    known = _finite(s, rows, "L_c")
    if not known:
        return "not computable: no point has large events"
    return ("L_c of the larger half of the large events' magnitudes over the smaller half's: "
            + "; ".join(f"{widest_zone_ratio(s, i)} ({_label(s, known, i)})" for i in known))


def _durations(s, rows):
    known = _finite(s, rows, "t_nucleation")
    if not known:
        return "not computable: no point has large events"
    initial = {i: s["points/numbers/t_initial"][i][0] for i in known}
    longest = max(known, key=lambda i: initial[i])
    growth = [s["points/numbers/t_nucleation"][i][0] - initial[i] for i in known]
    return (f"the initial phase {_span(initial.values())} time units (longest at {_label(s, known, longest)}), "
            f"the growth to the widest zone {_span(growth)} more (estimates; intervals: the table below)")


def nucleation_table(s, rows):
    """Every point's nucleation numbers with their intervals, a Markdown table (b, l and any other parameter that
    varies among the points first)."""
    keys = ["b", "l"] + [k for k in _varying(s, rows) if k not in ("b", "l")]
    out = ["| " + " | ".join(keys) + " | regime | large events | L_sc (onset zone, blocks) | initial phase (time) | "
           "L_c (widest zone, blocks) | L_c / l | to the widest zone (time) |", "|---" * (len(keys) + 7) + "|"]
    for i in sorted(rows, key=lambda i: [s[f"points/{k}"][i] for k in ("l", "b", *keys[2:])]):
        b, l, k = s["points/b"][i], s["points/l"][i], stiffness(s, i)
        regime = f"weak (b < 1 + 2 l^2 = {k:g})" if b < k else "strong" if b > k else "neutral (b = 1 + 2 l^2)"
        lc = s["points/numbers/L_c"][i][0]
        out.append("| " + " | ".join(f"{s[f'points/{key}'][i]:g}" for key in keys)
                   + f" | {regime} | {int(s['points/numbers/n_large'][i][0])} | {number(s, i, 'L_sc')} | "
                   f"{number(s, i, 't_initial')} | {number(s, i, 'L_c')} | {fmt(lc / l) if np.isfinite(lc) else '-'} | "
                   f"{number(s, i, 't_nucleation')} |")
    return "\n".join(out)


# -- Kawamura, Yamamoto & Ueda 2018: slow slip ------------------------------------------------------------------

def _value(s, i, name):
    return s[f"points/numbers/{name}"][i][0]


def _named(pool, names):
    """'l = 3, nu = 1e-08, a = 30, b = 15 (slow_slip_l3_nu1e-8)' of each (s, i, name) in `names`."""
    return "; ".join(f"{point_label(s, i, ['N', 'l', 'nu', 'a', 'b'])} ({name})" for s, i, name in names)


def _every(pool):
    return [(s, i, name) for s, rows, name in pool for i in rows]


def _mainshocks(pool):
    points = _every(pool)
    with_main = [p for p in points if _value(p[0], p[1], "n_main") > 0]
    total = sum(_value(s, i, "n_main") for s, i, _ in points)
    text = (f"mainshocks (inertial, mu >= mu_c) at {len(with_main)} of {len(points)} points, {total:.0f} in all, "
            f"{_span(_value(s, i, 'n_main') for s, i, _ in with_main)} per point" if with_main else
            f"no mainshock at any of the {len(points)} points")
    return text


def _precursors(pool):
    main = [p for p in _every(pool) if _value(p[0], p[1], "n_main") > 0]
    if not main:
        return "not computable: no mainshock"
    parts = []
    for label, keep in (("b below the block stiffness 1 + 2 l^2", lambda s, i: s["points/b"][i] < stiffness(s, i)),
                        ("b above it", lambda s, i: s["points/b"][i] > stiffness(s, i))):
        at = [(s, i) for s, i, _ in main if keep(s, i)]
        if at:
            count = sum(_value(s, i, "precursor_share") * _value(s, i, "n_main") for s, i in at)
            total = sum(_value(s, i, "n_main") for s, i in at)
            parts.append(f"{label}: {count:.0f} of {total:.0f} mainshocks at {len(at)} points, share per point "
                         f"{_span(_value(s, i, 'precursor_share') for s, i in at)}")
    return "precursory creep at or next to the epicenter: " + "; ".join(parts)


def _afterslip(pool):
    main = [p for p in _every(pool) if _value(p[0], p[1], "n_main") > 0]
    if not main:
        return "not computable: no mainshock"
    after = [p for p in main if _value(p[0], p[1], "afterslip_share") > 0]
    count = sum(_value(s, i, "afterslip_share") * _value(s, i, "n_main") for s, i, _ in after)
    total = sum(_value(s, i, "n_main") for s, i, _ in main)
    text = f"afterslip after {count:.0f} of {total:.0f} mainshocks, at {len(after)} of {len(main)} points"
    if after:
        text += ": " + "; ".join(f"{number(s, i, 'afterslip_share')} of {_value(s, i, 'n_main'):.0f}, its slip "
                                 f"{fmt(_value(s, i, 'afterslip_ratio'))} of theirs "
                                 f"({point_label(s, i, ['N', 'l', 'nu', 'a', 'b'])}, {name})" for s, i, name in after)
    return text


def _silent(pool):
    points = _every(pool)
    silent = [p for p in points if _value(p[0], p[1], "n_silent") > 0]
    text = (f"silent earthquakes (creep episodes that stopped by themselves with mu >= mu_c): "
            f"{sum(_value(s, i, 'n_silent') for s, i, _ in points):.0f} at {len(points)} points")
    if silent:
        text += ": " + "; ".join(f"{_value(s, i, 'n_silent'):.0f}, share of the large slips "
                                 f"{number(s, i, 'silent_share')} ({point_label(s, i, ['N', 'l', 'nu', 'a', 'b'])}, "
                                 f"{name})" for s, i, name in silent)
    return text


def _stable(pool):
    points = [p for p in _every(pool) if np.isfinite(_value(p[0], p[1], "aseismic_fraction"))]
    if not points:
        return "not computable: no creep at any point"
    s, i, name = max(points, key=lambda p: _value(p[0], p[1], "aseismic_fraction"))
    return (f"aseismic slip fraction (creep's share of all slip) at most {number(s, i, 'aseismic_fraction')} "
            f"({point_label(s, i, ['N', 'l', 'nu', 'a', 'b'])}, {name}) over {len(points)} points with creep")


# -- the claims, and what the command prints --------------------------------------------------------------------

@dataclass(frozen=True)
class Claim:
    statement: str                 # the paper's, as its abstract states it
    needs: tuple                   # the summary numbers it reads (a summary reduced before their statistic has none)
    where: dict                    # parameter -> the values a point may have ({}: any)
    vary: tuple                    # the parameters it runs over
    least: int                     # distinct values of `vary` it needs
    numbers: Callable              # (summary, its points) -> the numbers that test it, as text


@dataclass(frozen=True)
class Paper:
    reference: str
    claims: tuple                  # Claim, read from one summary each; or (statement, text of the pool) pairs
    pooled: bool = False           # the claims read every point of every summary that holds `needs`
    needs: tuple = ()
    table: Callable = None         # (summary, its points) -> a table of every point, after the claims


B20 = {"b": (20.0,)}
NUCLEATION = ("L_sc", "t_initial", "spread_share", "L_c", "t_nucleation")
PAPERS = (
    Paper("Kawamura, Ueda, Kakui, Morimoto & Yamamoto, Phys. Rev. E 95, 042122 (2017): statistical properties", (
        Claim("the rupture-length distribution is exponential at large sizes, exp(-L_r / L_0), with a seismic "
              "correlation length L_0", ("L0", "n_L0"), B20, ("N",), 1, _length),
        Claim("events fall into two classes: unilateral, with the epicenter at the rim of the rupture zone of the "
              "preceding event, and bilateral", ("fraction_unilateral", "uni_at_rim", "bi_at_rim"), B20, ("N",), 1,
              _classes),
        Claim("the bilateral events show enhanced characteristic (\"asperity\"-like) features", ("n_classified",),
              B20, ("N",), 1, _characteristic),
        Claim("the mean slip and the mean stress drop do not depend on L_r for large events",
              ("mean_slip_large", "slip_ratio", "mean_drop_large", "drop_ratio"), B20, ("N",), 1, _slip),
        Claim("seismic time correlations before and after the mainshock",
              ("foreshock_rate", "aftershock_rate", "background_rate", "quiescence_ratio", "doughnut_ratio"), B20,
              ("N",), 1, _correlations),
        Claim("L_0 in the continuum limit (about 100 km)", ("L0",), B20, ("l",), 2, _continuum))),
    Paper("Ueda, Morimoto, Kakui, Yamamoto & Kawamura, arXiv:1407.2693 (2015): the nucleation process", (
        Claim("a quasi-static initial phase and an unstable acceleration phase before the high-speed rupture",
              NUCLEATION, {}, ("b", "l"), 1, _phases),
        Claim("two nucleation lengths, their dependence on b and l", NUCLEATION, {}, ("b", "l"), 1, _lengths),
        Claim("the regimes of weak and strong frictional instability", NUCLEATION, {}, ("b", "l"), 1, _regimes),
        Claim("hardly dependent on the size of the ensuing mainshock", NUCLEATION, {}, ("b", "l"), 1, _size),
        Claim("the durations of each stage", NUCLEATION, {}, ("b", "l"), 1, _durations)), table=nucleation_table),
    Paper("Kawamura, Yamamoto & Ueda, arXiv:1805.07237 (2018): slow slip", (
        ("main shocks", _mainshocks),
        ("precursory nucleation", _precursors),
        ("afterslip", _afterslip),
        ("silent earthquakes", _silent),
        ("(stable sliding: not among the abstract's kinds; this code asks it too)", _stable)),
          pooled=True, needs=("n_main", "precursor_share", "afterslip_share", "afterslip_ratio", "n_silent",
                              "silent_share", "aseismic_fraction")),
)


def holds(s, names):
    return all(f"points/numbers/{n}" in s for n in names)


def _needs(claim):
    where = "".join(f" with {k} = " + " or ".join(f"{x:g}" for x in v) for k, v in claim.where.items())
    more = (f" and {WORDS.get(claim.least, claim.least)} or more values of {', '.join(claim.vary)}"
            if claim.least > 1 else "")
    return (f"not computed: needs points of the {PAPER_LAW} law{where}{more} in a summary that holds "
            + ", ".join(claim.needs))


def pool(paper, summaries, names):
    """[(summary, its points of the paper's law on a chain, name)] of the summaries holding the paper's numbers (the
    papers' models are chains: a plane's points are none of theirs)."""
    return [(s, [i for i, (law, shape) in enumerate(zip(summary.point_laws(s), summary.point_geometries(s)))
                 if law == PAPER_LAW and shape == CHAIN],
             Path(str(name)).name.removesuffix(".h5").removesuffix(".summary"))
            for s, name in zip(summaries, names) if holds(s, paper.needs)]


def section(paper, summaries, names):
    """One paper's lines: its claims table (and its table of every point)."""
    level = " / ".join(dict.fromkeys(level_text(s["attrs"]["level"]) for s in summaries))
    lines = [f"## {paper.reference}", "", f"| the paper (abstract) | this code ({level} intervals) |", "|---|---|"]
    if paper.pooled:
        points = pool(paper, summaries, names)
        for statement, numbers in paper.claims:
            text = numbers(points) if any(rows for _, rows, _ in points) else (
                f"not computed: needs points of the {PAPER_LAW} law in a summary that holds " + ", ".join(paper.needs))
            lines.append(f"| {statement} | {text} |")
        return lines
    found = [points_for(claim, summaries) for claim in paper.claims]
    for claim, f in zip(paper.claims, found):
        lines.append(f"| {claim.statement} | {claim.numbers(*f) if f else _needs(claim)} |")
    if paper.table and found[0]:
        s, rows = found[0]
        lines += ["", f"Every point ({names[next(k for k, x in enumerate(summaries) if x is s)]}):", "",
                  paper.table(s, rows)]
    return lines


def text(summaries, names):
    """Everything `analysis successors` prints."""
    lines = ["The successors' claims (the seed paper's authors, after it) beside this code's numbers", ""]
    for s, name in zip(summaries, names):
        lines.append(f"{name}: {size_text(s)}")
        if partial_text(s):
            lines.append(f"warning: {name}: {partial_text(s)}")
        lines += transients(s, name)
    for paper in PAPERS:
        lines += [""] + section(paper, summaries, names)
    return "\n".join(lines)
