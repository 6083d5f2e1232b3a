"""The paper's question, answered from regional summaries (docs/populations.md):

    python examples/populations/answer.py REGIONS.summary.h5 --faults FAULTS.summary.h5 -o docs/populations/NAME-answer

REGIONS: `analysis reduce CATALOG --region` (each point a region); FAULTS: `analysis reduce CATALOG` of the same
catalog (each fault a point of its own). For each region it gives, with 95% intervals over its faults:

- events in its window, GR b above the summary's b_cut (Aki) and the KS distance of mu >= b_cut from that law
  (the summary's numbers);
- the best two decades: for every stretch [lo, lo + 2) of mu (lo on the bins' edges, at least MIN_EVENTS events
  in it), the KS distance of the binned magnitudes from a Gutenberg-Richter law truncated to the stretch (b by
  maximum likelihood on the bins, within B_RANGE: a law that falls); the smallest of them and its lo, and its b.
  A region "looks critical" where that KS is below 0.05 (the working definition of the issue);
- the fraction of large events (mu >= mu_c) and the hump: R at the large-magnitude peak over R at the dip below
  it (analysis/paper.py's shape statistics, in bins of 0.1);
- the CV of the local recurrence times;
- beside them the single faults of the region: the median and the 5-95% range of their own KS to GR (each fault
  over all its recorded events).

Writes OUT.md (the table) and OUT.json (every number).
"""
import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from analysis import stats, summary
from analysis.paper import shape_statistics
from ensemble import space

DECADES = 2.0        # the stretch of mu a critical-looking region must follow GR over
MIN_EVENTS = 1000    # events a stretch needs for its KS distance to be read
RESAMPLES = 300      # bootstrap resamples of the faults for the two-decade KS
CRITICAL_KS = 0.05
HUMP_BIN = 0.1       # the hump is read in bins of 0.1 in mu (10 of the summary's 0.01): from 0.01 bins its dip is noise
# a Gutenberg-Richter law falls with mu: b is fitted within this range (a rising R(mu) is no GR law; at the lower
# end the fit is a flat R(mu), and its KS says how far the data are from even that)
B_RANGE = (0.01, 8.0)


def truncated_gr_ks(counts, edges):
    """(KS, b) of binned magnitudes on [edges[0], edges[-1]) against GR truncated to it, b by binned maximum
    likelihood. counts may be a stack of histograms (rows) on the same bins: then arrays of KS and b."""
    counts = np.asarray(counts, dtype=float)
    x = np.asarray(edges, dtype=float) - edges[0]
    rows = np.atleast_2d(counts)
    n = rows.sum(axis=1)

    def cdf(b):               # (rows, bins + 1): GR truncated to [0, width), one b per row
        k = (b * math.log(10))[:, None]
        flat = np.abs(k) < 1e-9
        with np.errstate(invalid="ignore", divide="ignore"):
            out = np.expm1(-k * x) / np.expm1(-k * x[-1])
        return np.where(flat, x / x[-1], out)

    def loglik(b):
        with np.errstate(divide="ignore"):
            return np.sum(rows * np.log(np.maximum(np.diff(cdf(b), axis=1), 1e-300)), axis=1)

    # golden-section search for the maximum of each row (the binned likelihood is unimodal in b)
    lo, hi = np.full(len(rows), B_RANGE[0]), np.full(len(rows), B_RANGE[1])
    g = (math.sqrt(5) - 1) / 2
    a, c = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fc = loglik(a), loglik(c)
    for _ in range(45):     # the bracket shrinks by 0.618^45 = 4e-10
        right = fa < fc         # the maximum lies in [a, hi]
        lo, hi = np.where(right, a, lo), np.where(right, hi, c)
        a, c = np.where(right, c, hi - g * (hi - lo)), np.where(right, lo + g * (hi - lo), a)
        fresh = np.where(right, c, a)
        f_new = loglik(fresh)
        fa, fc = np.where(right, fc, f_new), np.where(right, f_new, fa)
    b = (lo + hi) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        ks = np.max(np.abs(np.cumsum(rows, axis=1) / n[:, None] - cdf(b)[:, 1:]), axis=1)
    ks, b = np.where(n > 0, ks, np.nan), np.where(n > 0, b, np.nan)
    return (ks, b) if counts.ndim == 2 else (float(ks[0]), float(b[0]))


def best_decades(counts, edges):
    """(KS, lo, b) of the stretch [lo, lo + DECADES) with the smallest KS distance (MIN_EVENTS events in it)."""
    step = int(round(DECADES / np.diff(edges).mean()))
    starts = np.arange(0, len(edges) - step)
    windows = np.lib.stride_tricks.sliding_window_view(np.asarray(counts, dtype=float), step)[starts]
    enough = windows.sum(axis=1) >= MIN_EVENTS
    if not enough.any():
        return math.nan, math.nan, math.nan
    # equal bins: every stretch has the same bin offsets, so all are fitted at once
    ks, b = truncated_gr_ks(windows[enough], edges[:step + 1])
    i = int(np.argmin(ks))
    return float(ks[i]), float(edges[starts[enough][i]]), float(b[i])


def top_decades(counts, edges):
    """(KS, lo, b) of the stretch of DECADES below the top of the magnitudes (the bin edge above the 99.9th
    percentile of the events): the largest events, where a characteristic fault has its hump."""
    cum = np.cumsum(counts)
    if cum[-1] <= 0:
        return math.nan, math.nan, math.nan
    top = int(np.searchsorted(cum, 0.999 * cum[-1])) + 1
    step = int(round(DECADES / np.diff(edges).mean()))
    i = max(top - step, 0)
    ks, b = truncated_gr_ks(counts[i:top], edges[i:top + 1])
    return ks, float(edges[i]), b


def _with_interval(fn, per_fault, edges, rng, level):
    """fn(summed counts) of all the faults, and the interval of its first number over resampled faults."""
    est = fn(per_fault.sum(axis=0), edges)
    picks = rng.integers(0, len(per_fault), size=(RESAMPLES, len(per_fault)))
    draws = np.array([fn(per_fault[p].sum(axis=0), edges)[0] for p in picks])
    lo, hi = stats.percentile_interval(draws, level)
    return {"ks": [float(est[0]), float(lo), float(hi)], "lo": float(est[1]), "gr_b": float(est[2])}


def hump_merge(s):
    """The summary's bins merged into one of HUMP_BIN (1 where they are that wide or wider)."""
    return max(1, int(round(HUMP_BIN / float(np.diff(s["bins/mu"]).mean()))))


def region_rows(s, f=None, level=0.95, rng=None):
    rng = rng or np.random.default_rng(0)
    out = []
    for i in range(len(s["points/N"])):
        rows = np.flatnonzero(s["tasks/point"] == i)
        per_fault = summary.point_units(s, i)[1].sum(axis=1)    # (faults, bins)
        shape = shape_statistics(s, i, level, merge=hump_merge(s))
        row = {
            "region": s["points/region_label"][i], "faults": int(len(rows)),
            "span_tnu": float(s["points/region_span"][i]),
            **{name: [float(v) for v in s[f"points/numbers/{name}"][i]]
               for name in ("n_events", "gr_b", "ks_gr", "fraction_large", "cv_tnu") if f"points/numbers/{name}" in s},
            "hump": [float(v) for v in shape["peak_over_dip"][:3]], "peak_mu": [float(v) for v in shape["peak_mu"][:3]],
            "best_two_decades": _with_interval(best_decades, per_fault, s["bins/mu"], rng, level),
            "top_two_decades": _with_interval(top_decades, per_fault, s["bins/mu"], rng, level),
        }
        if f is not None:
            own, hists = _single_faults(s, rows, f)
            best = np.array([best_decades(h, f["bins/mu"])[0] for h in hists])
            top = np.array([top_decades(h, f["bins/mu"])[0] for h in hists])
            row.update({f"single_faults_{name}": _spread(v)
                        for name, v in (("ks_gr", own), ("best_two_decades", best), ("top_two_decades", top))})
        out.append(row)
    return out


def _spread(values):
    """The median and 5-95% range of the faults' values that could be computed, and how many could: None where none
    could (a fault needs MIN_EVENTS events in two decades of mu; in a small run none may have them)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not len(v):
        return {"median": None, "p5": None, "p95": None, "faults": 0}
    return {"median": float(np.median(v)), "p5": float(np.percentile(v, 5)), "p95": float(np.percentile(v, 95)),
            "faults": int(len(v))}


def _single_faults(s, rows, f):
    """KS to GR of each of the region's faults, and its histogram of mu over all its events, from the faults' summary
    (matched by their task)."""
    key = {(int(c), int(k)): g for g, (c, k) in enumerate(zip(f["tasks/catalog"], f["tasks/catalog_task"]))}
    tasks = [key[(int(s["tasks/catalog"][g]), int(s["tasks/catalog_task"][g]))] for g in rows]
    return f["points/numbers/ks_gr"][f["tasks/point"][tasks], 0], f["per_task/mu"][tasks].sum(axis=1).astype(float)


def table(rows):
    def iv(t, d=3):
        if not np.isfinite(t[0]):
            return f"- (fewer than {MIN_EVENTS} events)"
        return f"{t[0]:.{d}g} [{t[1]:.{d}g}, {t[2]:.{d}g}]"
    head = ("| region | faults | events | GR b | KS to GR (mu >= b_cut) | best two decades: KS (from mu, b) | "
            "top two decades: KS (from mu, b) | large (mu >= mu_c) | hump: peak / dip | CV of T nu | "
            "single faults' KS to GR / best / top two decades (median, 5-95%) |")
    lines = [head, "|" + " --- |" * (head.count("|") - 1)]
    def decades(d):
        if not np.isfinite(d["ks"][0]):
            return f"- (no two decades with {MIN_EVENTS} events)"
        return f"{iv(d['ks'])} (from {d['lo']:g}, b {d['gr_b']:.3g})"

    def spread(d):
        if d["median"] is None:
            return "- (no fault has enough events)"
        return f"{d['median']:.3g} ({d['p5']:.3g}-{d['p95']:.3g})"
    for r in rows:
        single = " / ".join(spread(r[f"single_faults_{n}"]) for n in ("ks_gr", "best_two_decades", "top_two_decades")
                            if f"single_faults_{n}" in r) or "-"
        lines.append(f"| {r['region']} | {r['faults']} | {r['n_events'][0]:.0f} | {iv(r['gr_b'])} | {iv(r['ks_gr'])} | "
                     f"{decades(r['best_two_decades'])} | {decades(r['top_two_decades'])} | "
                     f"{iv(r['fraction_large'])} | "
                     f"{iv(r['hump'])} | {iv(r['cv_tnu']) if 'cv_tnu' in r else '-'} | {single} |")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("regions", help="a regional summary (analysis reduce --region)")
    p.add_argument("--faults", help="the same catalog reduced fault by fault (analysis reduce)")
    p.add_argument("-o", "--output", required=True, help="OUT: writes OUT.md and OUT.json")
    args = p.parse_args(argv)
    s = summary.read(args.regions)
    if "points/region" not in s:
        print(f"error: {args.regions} is not a regional summary (analysis reduce --region)", file=sys.stderr)
        return 2
    rows = region_rows(s, summary.read(args.faults) if args.faults else None, float(s["attrs"]["level"]))
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    # (OUT + suffix: a dot in OUT is kept)
    space.write_file(f"{out}.json", json.dumps(rows, indent=1), "the answer's numbers")
    space.write_file(f"{out}.md", table(rows) + "\n", "the answer's table")
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
