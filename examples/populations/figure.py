"""The figure of docs/populations.md and the README: does a region of many characteristic faults look critical?

    python examples/populations/figure.py REGIONS.summary.h5 ANSWER.json [MORE.summary.h5 MORE.json ...] \
        [--columns 3] -o docs/populations/regions.png

REGIONS: `analysis reduce CATALOG --region --mu-bins 0:7:700`; ANSWER.json: what examples/populations/answer.py
wrote from it. One panel per region: its R(mu) in bins of 0.1 with its 95% band (a bootstrap over its faults), the
5-95% range of its single faults' own R(mu) (each in its window) in grey, the Gutenberg-Richter law fitted to its
best two decades (answer.py) over them, and a law of slope b = 2/3 (a real catalog's, in mu = log10 of the slip)
through the same point. A last panel: the KS distance of the best and of
the top two decades, each region's with its interval over faults beside its single faults' 5-95% range, and the
working definition of critical, KS < 0.05.
"""
import argparse
import json
import math
import re
import sys
import warnings
from pathlib import Path

import numpy as np

from analysis import stats, summary
from analysis.drawing import FONT, band, save
from analysis.plot import plt
from analysis.stats import centers

REAL_B = 2 / 3       # GR b of a real catalog (about 1 in moment magnitude) in mu = log10 of the slip
CRITICAL_KS = 0.05
MIN_EVENTS = 1000    # events two decades need for a fit (answer.py's MIN_EVENTS)
DRAWN_BIN = 0.1      # R(mu) drawn in bins of 0.1 (10 of the summary's 0.01), or the summary's own where coarser


def merge_of(s):
    """Bins of the summary merged into one drawn bin: DRAWN_BIN over the summary's width, at least 1."""
    width = float(np.diff(s["bins/mu"]).mean())
    return max(1, int(round(DRAWN_BIN / width)))
RESAMPLES = 1000


def merged(s, i, merge):
    """Region i's faults in bins of `merge` of the summary's: (edges, counts (faults, bins), events per fault in
    and out of range)."""
    edges, counts, events = summary.point_units(s, i, merge)
    return edges, counts.sum(axis=1), events.sum(axis=1)


def gr_line(edges, r, fit):
    """(mu, R) of the truncated GR law fitted on [lo, lo + 2): the region's share of events there, spread as the law."""
    lo, b = fit["lo"], fit["gr_b"]
    inside = (centers(edges) >= lo) & (centers(edges) < lo + 2)
    share = float(np.sum(r[inside] * np.diff(edges)[inside]))
    # drawn where the region has events: a fit at the top of the magnitudes may reach past the last of them
    reached = edges[1:][r > 0]
    mu = np.linspace(lo, min(lo + 2, reached.max() if len(reached) else lo + 2), 50)
    k = b * math.log(10)
    return mu, share * k * np.exp(-k * (mu - lo)) / -math.expm1(-2 * k)


def region_panel(ax, s, i, row, merge, level, rng):
    edges, counts, events = merged(s, i, merge)
    c = centers(edges)
    faults = stats.density(counts, edges, events[:, None])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)       # a bin no fault reaches
        p5, p95 = np.nanpercentile(np.where(faults > 0, faults, np.nan), [5, 95], axis=0)
    ok = np.isfinite(p5) & np.isfinite(p95)
    ax.fill_between(c[ok], p5[ok], p95[ok], color="0.85", lw=0, label="single faults: 5-95%", zorder=1)
    units = np.concatenate([counts, events[:, None]], axis=1)
    r = stats.density(counts.sum(axis=0), edges, events.sum())
    lo, hi = stats.percentile_interval(stats.bootstrap(
        units, lambda u: stats.density(u[:-1], edges, u[-1]), RESAMPLES, rng), level)
    band(ax, c, r, lo, hi, "the region (band: its faults resampled)", "C0", log=True, open_ends=True)
    fit = row["best_two_decades"]
    if np.isfinite(fit["ks"][0]):
        mu, gr = gr_line(edges, r, fit)
        ax.plot(mu, gr, color="C3", lw=1.5, label="GR law fitted to the best two decades", zorder=4)
        ax.text(0.03, 0.03, f"best two decades: b = {fit['gr_b']:.2f}, KS = {fit['ks'][0]:.3f}",
                transform=ax.transAxes, fontsize=FONT - 1)
        ax.plot(mu, gr[0] * 10 ** (-REAL_B * (mu - mu[0])), color="k", ls="--", lw=1,
                label="slope of a real catalog (b = 2/3)", zorder=4)
    else:
        ax.text(0.03, 0.03, f"no two decades with {MIN_EVENTS} events: no GR fit", transform=ax.transAxes,
                fontsize=FONT - 1)
    ax.set_yscale("log")
    ax.set_ylim(1e-4, 5)
    ax.set_xlabel(r"magnitude $\mu$")
    ax.set_title(row["region"].split(";")[0] + f"\n{row['faults']} faults, {row['n_events'][0]:.3g} events",
                 fontsize=FONT)


def short_label(region):
    """'N: power 1.66667 on [2, 200]; b: ...' -> 'N^-1.67\n2-200' (the drawn N); else the region's first key."""
    m = re.match(r"N: power ([\d.e+-]+) on \[(\S+), (\S+)\]", region)
    return f"N^-{float(m[1]):.3g}\n{m[2]}-{m[3]}" if m else region.split(";")[0]


def ks_panel(ax, rows):
    x = np.arange(len(rows))
    for shift, key, color, name in ((-0.12, "best_two_decades", "C3", "best two decades"),
                                    (0.12, "top_two_decades", "C1", "top two decades")):
        est = np.array([r[key]["ks"] for r in rows])
        # (a distance's resamples may all lie above the estimate: the interval is drawn as it is, apart)
        ax.vlines(x + shift, est[:, 1], est[:, 2], color=color, lw=1.5, zorder=3)
        ax.plot(x + shift, est[:, 0], "o", color=color, label=f"region, {name} (95% over faults)", zorder=3)
        single = [r.get(f"single_faults_{key}") for r in rows]
        if all(d and d["median"] is not None for d in single):     # (None: no fault had the events for it)
            ax.vlines(x + shift + 0.06, [d["p5"] for d in single], [d["p95"] for d in single], color="0.6", lw=3,
                      label="single faults' KS: 5-95%" if key == "best_two_decades" else None)
            ax.plot(x + shift + 0.06, [d["median"] for d in single], "_", color="k", ms=8,
                    label="single faults' KS: median" if key == "best_two_decades" else None)
    ax.axhline(CRITICAL_KS, color="k", ls=":", lw=1, label="critical: KS < 0.05")
    ax.set_yscale("log")
    ax.set_xticks(x, [short_label(r["region"]) for r in rows], fontsize=FONT - 1)
    ax.set_ylabel("KS distance to a truncated GR law")
    ax.set_title("two decades of mu against GR", fontsize=FONT)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("pairs", nargs="+", metavar="REGIONS ANSWER",
                   help="a regional summary in bins of 0.01 (analysis reduce --region --mu-bins 0:7:700) and the "
                        "ANSWER.json examples/populations/answer.py wrote from it; several pairs: their regions "
                        "in rows of COLUMNS panels")
    p.add_argument("--columns", type=int, default=0, help="panels per row (default: all in one row)")
    p.add_argument("-o", "--output", required=True)
    args = p.parse_args(argv)
    if len(args.pairs) % 2:
        print("error: give pairs of a regional summary and its ANSWER.json", file=sys.stderr)
        return 2
    regions = []
    for path, answer in zip(args.pairs[::2], args.pairs[1::2]):
        s = summary.read(path)
        rows = json.loads(Path(answer).read_text())
        if [r["region"] for r in rows] != list(s["points/region_label"]):
            print(f"error: {answer} is not the answer of {path}'s regions", file=sys.stderr)
            return 2
        regions += [(s, i, row) for i, row in enumerate(rows)]
    panels = len(regions) + 1
    columns = args.columns or panels
    nrows = -(-panels // columns)
    # the legend beneath the panels: its columns (about 4 inches each) as many as the figure's width holds
    ncol = max(1, min(4, columns))
    legend_rows = -(-7 // ncol)          # its entries: at most seven
    height = 4.3 * nrows + 0.3 + 0.25 * legend_rows      # inches: the panels, and the legend beneath them
    fig, axes = plt.subplots(nrows, columns, figsize=(4.2 * columns, height), squeeze=False)
    axes = axes.ravel()
    for k, (ax, (s, i, row)) in enumerate(zip(axes, regions)):
        region_panel(ax, s, i, row, merge_of(s), float(s["attrs"]["level"]), np.random.default_rng(k))
        if k:
            ax.sharey(axes[0])
        if k % columns == 0:
            ax.set_ylabel(r"$R(\mu)$")
    handles, texts = axes[0].get_legend_handles_labels()
    ks_panel(axes[len(regions)], [row for _, _, row in regions])
    for ax in axes[panels:]:
        ax.set_visible(False)
    h2, t2 = axes[len(regions)].get_legend_handles_labels()
    fig.legend(handles + h2, texts + t2, loc="lower center", ncol=ncol, fontsize=FONT, bbox_to_anchor=(0.5, 0.0))
    s0 = regions[0][0]
    names = ", ".join(path.rsplit("/", 1)[-1].removesuffix(".region.summary.h5") for path in args.pairs[::2])
    fig.suptitle(f"{names}: regions of {regions[0][2]['faults']} faults; l = {s0['points/l'][0]:g}, "
                 f"a = {s0['points/a'][0]:g}, c = {s0['points/c'][0]:g}, nu = {s0['points/nu'][0]:g}; "
                 f"R(mu) in bins of {merge_of(s0) * float(np.diff(s0['bins/mu']).mean()):.2g}, bands: 95% "
                 "bootstrap over faults", fontsize=FONT + 1, wrap=True)
    fig.tight_layout(rect=(0, (0.3 + 0.25 * legend_rows) / height, 1, 0.95))
    save(fig, args.output, dpi=110)
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
