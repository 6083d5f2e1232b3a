"""The tables of docs/paper.md from the committed full-size summaries (docs/paper/*.summary.h5).

    python examples/paper/tables.py [DIR]  > docs/paper/tables.md      (DIR default docs/paper)

1. The runs: per task its parameters, events, wall time and events/s as the runner recorded them
   (events/s: recorded events per second of kernel time; the wall time is that of the task's
   last run segment, so a task resumed after an interruption is marked and undercounted).
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
FLAT = (3.0, 5.5)          # a flat R(mu): max / min of R over this range (above the few-block events)


PANELS = ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b")


def load(d):
    """{panel: its summary, or None where it has not been reduced}, each read once."""
    paths = {name: Path(d) / f"{name}.summary.h5" for name in PANELS}
    return {name: summary.read(path) if path.exists() else None for name, path in paths.items()}


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


def runs_table(panels):
    out = ["| run | N | a | b | c | events | wall time [s] | events/s |", "|---|---|---|---|---|---|---|---|"]
    total_events = total_wall = 0.0
    for name, s in panels.items():
        if s is None:
            out.append(f"| {name} | not run yet | | | | | | |")
            continue
        for k in range(len(s["tasks/N"])):
            events, wall = int(s["tasks/events_written"][k]), float(s["tasks/wall_time"][k])
            total_events += events
            total_wall += wall
            rate = float(s["tasks/events_per_second"][k])
            # wall_time covers the task's last run segment only: after a resume it misses the
            # part before (recognised by a wall time too short for the recorded events)
            resumed = wall * rate < 0.9 * events
            out.append(f"| {name} | {int(s['tasks/N'][k])} | {s['tasks/a'][k]:g} | {s['tasks/b'][k]:g} | "
                       f"{s['tasks/c'][k]:g} | {events} | {wall:.0f}{' (after a resume)' if resumed else ''} | "
                       f"{rate:.0f} |")
    out.append(f"\nAll tasks: {int(total_events)} events in {total_wall:.0f} s of task time "
               f"({total_wall / 3600:.2f} core-hours).")
    return "\n".join(out)


def listing(s, rows, value, label):
    """'v1, v2, ... (label = x1, x2, ...)' over the points `rows` of summary s."""
    return (", ".join(value(i) for i in rows) + f" ({label} = "
            + ", ".join(f"{s[f'points/{label}'][i]:g}" for i in rows) + ")")


def claims_table(panels):
    """One row per claim of the paper: the claim, and the full-size numbers that test it."""
    b, a, c, f2, lb = (panels[n] for n in PANELS)
    out = ["| the paper (Ohmura & Kawamura 2007) | full size, this code (95% intervals) |", "|---|---|"]
    if b is not None:
        bs = [point_of(b, b=x) for x in (20.0, 30.0, 40.0, 50.0)]
        sh = shape_statistics(b, bs[0])
        out.append("| b = 20: R(mu) has a characteristic peak at large magnitude | peak at mu = "
                   f"{with_interval(sh['peak_mu'])}, {with_interval(sh['peak_over_dip'])} times R at the dip "
                   f"below it (mu = {with_interval(sh['dip_mu'])}) |")
        out.append("| b = 30..50: a flatter R(mu), no deep dip | max / min of R over 3 <= mu <= 5.5: "
                   + listing(b, bs[1:], lambda i: with_interval(shape_statistics(b, i)["flat_spread"]), "b")
                   + f"; {with_interval(sh['flat_spread'])} for b = 20 |")
        out.append("| R(mu) is not a Gutenberg-Richter power law | KS distance of R(mu) to the fitted power law "
                   "(GR b above mu = 3): " + listing(b, bs, lambda i: number(b, i, "ks_gr"), "b") + " |")
    if a is not None:
        rows = [point_of(a, a=x) for x in (0.0, 10.0, 20.0, 30.0)]
        out.append("| little dependence on a (b = 50) | fraction of events with mu >= 4: "
                   + listing(a, rows, lambda i: number(a, i, "fraction_large"), "a") + " |")
    if c is not None:
        rows = [point_of(c, c=x) for x in (100.0, 1000.0, 10000.0)]
        out.append("| little dependence on c (b = 20) | fraction of events with mu >= 4: "
                   + listing(c, rows, lambda i: number(c, i, "fraction_large"), "c")
                   + "; c drops out of the equations exactly (a shift of u): one model, three trajectories |")
    if f2 is not None:
        for bb, claim in ((20.0, "b = 20: a sharp recurrence peak near T nu ~ 500"),
                          (40.0, "b = 40: two recurrence peaks")):
            rows = [point_of(f2, b=bb, N=n) for n in (800, 1600)]
            out.append(f"| {claim} | T nu at the peaks: " + listing(f2, rows, lambda i: peaks(f2, i), "N") + " |")
    if lb is not None:
        rows = [point_of(lb, b=x) for x in (60.0, 80.0, 100.0)]
        out.append("| larger b (60, 80, 100): a preliminary study | fraction of events with mu >= 4: "
                   + listing(lb, rows, lambda i: number(lb, i, "fraction_large"), "b") + "; KS distance to GR: "
                   + listing(lb, rows, lambda i: number(lb, i, "ks_gr"), "b") + "; max / min of R over 3..5.5: "
                   + listing(lb, rows, lambda i: with_interval(shape_statistics(lb, i)["flat_spread"]), "b") + " |")
    return "\n".join(out)


# Points that are one model in several panels (c drops out exactly, so every b = 20, a = 0, N = 800
# point is the same model): independent trajectories whose spread tests the intervals.
SAME_MODEL = {"b = 20, a = 0, N = 800": [("fig1_b", {"b": 20.0}), ("fig1_c", {"c": 100.0}), ("fig1_c", {"c": 1000.0}),
                                         ("fig1_c", {"c": 10000.0}), ("fig2", {"b": 20.0, "N": 800})],
              "b = 50, a = 0, N = 800": [("fig1_b", {"b": 50.0}), ("fig1_a", {"a": 0.0})]}


def consistency_table(panels):
    """Per model and number: the trajectories' values and chi^2 / dof of their spread."""
    out = ["| model | number | independent trajectories | chi^2 / dof |", "|---|---|---|---|"]
    for model, members in SAME_MODEL.items():
        found = [(name, panels[name], params) for name, params in members]
        found = [(name, s, point_of(s, **params), params) for name, s, params in found if s is not None]
        if len(found) < 2:
            continue
        for key in ("fraction_large", "gr_b", "ks_gr", "mean_tnu"):
            rows = np.array([s[f"points/numbers/{key}"][i] for _, s, i, _ in found])
            sigma = (rows[:, 2] - rows[:, 1]) / (2 * 1.96)
            w = 1 / sigma ** 2
            mean = np.sum(w * rows[:, 0]) / np.sum(w)
            chi2 = np.sum(w * (rows[:, 0] - mean) ** 2) / (len(rows) - 1)
            values = "; ".join(f"{fmt(r[0], 4)} ({name} {', '.join(f'{k} = {v:g}' for k, v in params.items())})"
                               for r, (name, _, _, params) in zip(rows, found))
            out.append(f"| {model} | {key} | {values} | {chi2:.2f} ({len(rows) - 1}) |")
    return "\n".join(out)


def main(d="docs/paper"):
    panels = load(d)
    print("<!-- written by `python examples/paper/tables.py` from docs/paper/*.summary.h5 -->")
    print("## Runs\n")
    print(runs_table(panels))
    print("\n## The paper's claims at full size\n")
    print(claims_table(panels))
    print("\n## One model, independent trajectories\n")
    print("c drops out of the equations exactly, so every b = 20, a = 0, N = 800 point of the panels is one "
          "model; each panel ran it from its own seed. chi^2 / dof of the values about their weighted mean, "
          "sigma = 95% half-width / 1.96: about 1 if the intervals are right, much more if too narrow.\n")
    print(consistency_table(panels))


if __name__ == "__main__":
    main(*sys.argv[1:])
