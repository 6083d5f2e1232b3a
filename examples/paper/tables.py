"""The tables of docs/paper.md from the committed full-size summaries (docs/paper/*.summary.h5).

    python examples/paper/tables.py [DIR]  > docs/paper/tables.md      (DIR default docs/paper)

1. The runs: per task its parameters, events, wall time and events/s as the runner recorded them
   (summed over resumes; events/s counts the transient too).
2. The paper's claims beside the full-size numbers. Numbers the report prints (fraction of large
   events, GR b, KS distance, mode and peaks of T nu) are the summary's, with its 95% intervals.
   The shape of R(mu) (the large-magnitude peak, the dip below it, their ratio, the spread of a
   flat R(mu)) is computed here from the summary's per-stretch histograms, with percentile
   intervals from 1000 resamples of the same units (analysis.stats.bootstrap, seed 0).
"""
import sys
from pathlib import Path

import numpy as np

from analysis import stats, summary

LEVEL = 0.95
RESAMPLES = 1000
PEAK_FROM = 3.5            # the large-magnitude peak: the maximum of R(mu) for mu >= PEAK_FROM
DIP_FROM = 2.5             # the dip: the minimum of R(mu) between DIP_FROM and the peak
FLAT = (2.5, 5.5)          # a flat R(mu): max / min of R over this range


def load(d, name):
    path = Path(d) / f"{name}.summary.h5"
    return summary.read(path) if path.exists() else None


def point_of(s, **params):
    rows = [i for i in range(len(s["points/N"])) if all(s[f"points/{k}"][i] == v for k, v in params.items())]
    assert len(rows) == 1, (params, rows)
    return rows[0]


def fmt(v, digits=3):
    return f"{v:.{digits}g}"


def with_interval(triple, digits=3):
    est, lo, hi = triple
    return f"{fmt(est, digits)} [{fmt(lo, digits)}, {fmt(hi, digits)}]"


def number(s, i, name, digits=3):
    return with_interval(s[f"points/numbers/{name}"][i], digits)


def shape_statistics(s, i):
    """R(mu) shape numbers of point i with bootstrap intervals over its units (stretches)."""
    edges = s["bins/mu"]
    c = stats.centers(edges)
    tasks = np.flatnonzero(s["tasks/point"] == i)
    units = s["per_task/mu"][tasks].reshape(-1, len(c))
    total_events = s["per_task/numbers"][tasks].reshape(-1, s["per_task/numbers"].shape[-1])[:, stats.N_EVENTS]
    rows = np.concatenate([units, total_events[:, None]], axis=1)

    def shape(row):
        r = stats.density(row[:-1], edges, row[-1])
        big = np.flatnonzero(c >= PEAK_FROM)
        k = big[np.argmax(r[big])]
        below = np.flatnonzero((c >= DIP_FROM) & (c <= c[k]))
        j = below[np.argmin(r[below])]
        flat = np.flatnonzero((c >= FLAT[0]) & (c <= FLAT[1]))
        with np.errstate(divide="ignore"):
            return np.array([c[k], r[k], c[j], r[j], r[k] / r[j], r[flat].max() / r[flat].min()])

    est = shape(rows.sum(axis=0))
    samples = stats.bootstrap(rows, shape, RESAMPLES, np.random.default_rng(0))
    lo, hi = stats.percentile_interval(samples, LEVEL)
    keys = ("peak_mu", "peak_r", "dip_mu", "dip_r", "peak_over_dip", "flat_spread")
    return {k: (est[n], lo[n], hi[n]) for n, k in enumerate(keys)}


def peaks(s, i):
    rows = s["points/peaks"][i]
    rows = rows[np.isfinite(rows[:, 0])]
    return "; ".join(with_interval(r, 4) for r in sorted(rows, key=lambda r: r[0])) or "none"


def runs_table(d):
    out = ["| run | N | a | b | c | events | wall time [s] | events/s |", "|---|---|---|---|---|---|---|---|"]
    total_events = total_wall = 0.0
    for name in ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b"):
        s = load(d, name)
        if s is None:
            out.append(f"| {name} | not run yet | | | | | | |")
            continue
        for k in range(len(s["tasks/N"])):
            events, wall = int(s["tasks/events_written"][k]), float(s["tasks/wall_time"][k])
            total_events += events
            total_wall += wall
            out.append(f"| {name} | {int(s['tasks/N'][k])} | {s['tasks/a'][k]:g} | {s['tasks/b'][k]:g} | "
                       f"{s['tasks/c'][k]:g} | {events} | {wall:.0f} | {float(s['tasks/events_per_second'][k]):.0f} |")
    out.append(f"\nAll tasks: {int(total_events)} events in {total_wall:.0f} s of task time "
               f"({total_wall / 3600:.2f} core-hours).")
    return "\n".join(out)


def claims_table(d):
    b, a, c, f2, lb = (load(d, n) for n in ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b"))
    out = ["| the paper (Ohmura & Kawamura 2007) | full size (this code), 95% intervals |", "|---|---|"]
    if b is not None:
        i20 = point_of(b, b=20.0)
        sh = shape_statistics(b, i20)
        out.append("| b = 20: R(mu) has a characteristic peak at large magnitude | peak at mu = "
                   f"{with_interval(sh['peak_mu'])}, R = {with_interval(sh['peak_r'])}; below it a dip to R = "
                   f"{with_interval(sh['dip_r'])} at mu = {with_interval(sh['dip_mu'])}: peak / dip = "
                   f"{with_interval(sh['peak_over_dip'])}; {number(b, i20, 'fraction_large')} of events have "
                   "mu >= 4 |")
        flat = [(bb, shape_statistics(b, point_of(b, b=bb))["flat_spread"]) for bb in (30.0, 40.0, 50.0)]
        out.append("| b = 30..50: R(mu) flatter, no deep dip | max / min of R over 2.5 <= mu <= 5.5: "
                   + "; ".join(f"{with_interval(v)} (b = {bb:g})" for bb, v in flat)
                   + f", against {with_interval(sh['flat_spread'])} for b = 20 |")
        gr = "; ".join(f"b = {bb:g}: GR b {number(b, point_of(b, b=bb), 'gr_b')}, KS "
                       f"{number(b, point_of(b, b=bb), 'ks_gr')}" for bb in (20.0, 30.0, 40.0, 50.0))
        out.append(f"| R(mu) is not a Gutenberg-Richter power law | {gr} (GR b from mu >= 3; KS distance of "
                   "R(mu) to the fitted law) |")
    if a is not None:
        rows = [point_of(a, a=x) for x in (0.0, 10.0, 20.0, 30.0)]
        out.append("| little dependence on a (b = 50) | fraction mu >= 4: "
                   + "; ".join(f"{number(a, i, 'fraction_large')} (a = {a['points/a'][i]:g})" for i in rows)
                   + "; GR b: " + "; ".join(number(a, i, "gr_b") for i in rows) + " |")
    if c is not None:
        rows = [point_of(c, c=x) for x in (100.0, 1000.0, 10000.0)]
        out.append("| little dependence on c (b = 20) | fraction mu >= 4: "
                   + "; ".join(f"{number(c, i, 'fraction_large')} (c = {c['points/c'][i]:g})" for i in rows)
                   + "; GR b: " + "; ".join(number(c, i, "gr_b") for i in rows)
                   + "; c drops out of the equations exactly here (a shift of u), so these are "
                     "independent samples of one model |")
    if f2 is not None:
        for bb, claim in ((20.0, "b = 20: a sharp recurrence peak, T nu ~ 500"),
                          (40.0, "b = 40: two recurrence peaks")):
            parts = []
            for n in (800, 1600):
                i = point_of(f2, b=bb, N=n)
                parts.append(f"N = {n}: mode {number(f2, i, 'mode_tnu', 4)}, peaks {peaks(f2, i)}; mean T nu "
                             f"{number(f2, i, 'mean_tnu', 4)} (interior {number(f2, i, 'mean_tnu_interior', 4)})")
            out.append(f"| {claim} | " + "; ".join(parts) + " |")
    if lb is not None:
        rows = [point_of(lb, b=x) for x in (60.0, 80.0, 100.0)]
        out.append("| larger b (60, 80, 100): a preliminary study in the paper | "
                   + "; ".join(f"b = {lb['points/b'][i]:g}: fraction mu >= 4 {number(lb, i, 'fraction_large')}, "
                               f"GR b {number(lb, i, 'gr_b')}, KS {number(lb, i, 'ks_gr')}, R(mu) max / min over "
                               f"2.5..5.5 {with_interval(shape_statistics(lb, i)['flat_spread'])}" for i in rows)
                   + " |")
    return "\n".join(out)


def main(d="docs/paper"):
    print("<!-- written by `python examples/paper/tables.py` from docs/paper/*.summary.h5 -->")
    print("## Runs\n")
    print(runs_table(d))
    print("\n## The paper's claims at full size\n")
    print(claims_table(d))


if __name__ == "__main__":
    main(*sys.argv[1:])
