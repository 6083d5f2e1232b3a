"""Discreteness, the other suspect (docs/populations.md): the chain toward its continuum limit at a fixed physical
length, from one summary per l:

    python examples/populations/discreteness.py L3.summary.h5 L6.summary.h5 L12.summary.h5 > OUT.md

Each summary is `analysis reduce` of one catalog of examples/populations/discrete_l*.toml (N = 400 l / 3 blocks),
reduced with the large-event threshold and the recurrence window scaled with the blocks per unit length
(--mu-c 4 + log10(N / 400), --b-cut 3 + log10(N / 400), --window 10 N / 400), so that both mean the same physical
size at every l. A block's slip is a physical length at every l (the units are those of one block's plate spring
and friction, both proportional to its length), so mu' = mu - log10(N / 400) is the magnitude of the same physical
moment; R(mu)'s
shape (its peak over the dip below it) is read on mu'. Each number with its 95% interval (over the summary's
units: seeds, or stretches of every trajectory with fewer than 10).
"""
import math
import sys

import numpy as np

from analysis import summary
from analysis.paper import DIP_FROM, ratio, shape_statistics, with_interval

REFERENCE_N = 400     # the l = 3 chain's length: mu' = mu - log10(N / REFERENCE_N)


def dip(quad, edges):
    """The peak over the dip, or, where a bin between the dip's start and the peak holds no event, that said."""
    if math.isinf(quad[0]):
        return f"unbounded: a bin of {np.diff(edges).mean():.2g} from mu' = {DIP_FROM:g} to the peak holds no event"
    return ratio(quad, "the dip bin")


def row(path):
    s = summary.read(path)
    if len(s["points/N"]) != 1:
        raise SystemExit(f"error: {path} has {len(s['points/N'])} points; one l per summary")
    n, l = float(s["points/N"][0]), float(s["points/l"][0])
    shift = math.log10(n / REFERENCE_N)
    shifted = dict(s)
    shifted["bins/mu"] = s["bins/mu"] - shift
    shape = shape_statistics(shifted, 0)

    def num(name):
        return with_interval(s[f"points/numbers/{name}"][0]) if f"points/numbers/{name}" in s else "-"
    return (f"| {l:g} | {n:.0f} | {float(s['attrs']['mu_c']):.2f} | {num('n_events')} | {num('creep_share')} | "
            f"{num('fraction_large')} | {with_interval(shape['peak_mu'][:3])} | "
            f"{dip(shape['peak_over_dip'], s['bins/mu'])} | "
            f"{num('cv_tnu')} | {num('ks_gr')} |")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    print("| l | N | mu_c | inertial events | creep share of rows | fraction mu >= mu_c | peak of R at mu' | "
          "peak / dip | CV of local T nu | KS to GR (mu >= b_cut) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for path in argv:
        print(row(path))
    return 0


if __name__ == "__main__":
    sys.exit(main())
