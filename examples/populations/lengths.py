"""Where a single fault's large events lie, by its length (docs/populations.md):

    python examples/populations/lengths.py runs/populations/lengths.h5 > docs/populations/lengths.md
    python examples/populations/lengths.py runs/populations/regions.h5 --fit-only

One row per task of the catalog (examples/populations/lengths.toml): N, b, the inertial events per unit of
loading (T nu), the 50th, 90th and 99th percentiles of mu, and the fraction of events with mu >= 4. Then the
least-squares line of the median mu on log10 N over the faults whose every event ruptures the whole fault
(p99 - p50 below 0.3): mu = slope log10 N + intercept. Then, over the faults with N >= 100 and at least 20
events with mu >= 4 (a population's faults, say), the least-squares planes of the median mu of those large
events and of the log10 of their rate per unit of loading on log10 N and b.
"""
import sys

import numpy as np

from ensemble.store import reader
from ensemble.store.schema import KIND_EVENT

NU_UNITS = "T nu"


def rows(path):
    with reader.Reader(path) as cat:
        nu = float(cat.tasks["nu"][0])
        for k in range(len(cat.tasks["point"])):
            keep = cat.column(k, "kind") == KIND_EVENT
            t, mu = cat.column(k, "t")[keep], cat.column(k, "mu")[keep]
            span = (t[-1] - t[0]) * nu
            large = mu[mu >= 4]
            yield (float(cat.tasks["N"][k]), float(cat.tasks["b"][k]), (len(mu) - 1) / span,
                   *np.percentile(mu, [50, 90, 99]), float(np.mean(mu >= 4)),
                   float(np.median(large)) if len(large) >= 20 else np.nan, len(large) / span)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    fit_only = "--fit-only" in argv
    argv = [a for a in argv if a != "--fit-only"]
    if len(argv) != 1:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    table = np.array(list(rows(argv[0])))
    if not fit_only:
        print(f"| N | b | events per {NU_UNITS} | mu: p50 | p90 | p99 | fraction mu >= 4 |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
        for N, b, rate, p50, p90, p99, large, *_ in table:
            print(f"| {N:.0f} | {b:g} | {rate:.3g} | {p50:.2f} | {p90:.2f} | {p99:.2f} | {large:.3f} |")
        whole = table[:, 5] - table[:, 3] < 0.3
        print()
        for b in np.unique(table[whole, 1]):
            sel = whole & (table[:, 1] == b)
            slope, intercept = np.polyfit(np.log10(table[sel, 0]), table[sel, 3], 1)
            print(f"b = {b:g}: faults ruptured whole in every event: "
                  f"N = {', '.join(f'{n:.0f}' for n in table[sel, 0])}; "
                  f"median mu = {slope:.3f} log10 N + {intercept:.3f}")
    long = (table[:, 0] >= 100) & np.isfinite(table[:, 7])
    if long.sum() >= 3:
        x = np.c_[np.log10(table[long, 0]), table[long, 1], np.ones(long.sum())]
        for name, y in (("median mu of the events with mu >= 4", table[long, 7]),
                        (f"log10 of their rate per {NU_UNITS}", np.log10(table[long, 8]))):
            (p, q, r), *_ = np.linalg.lstsq(x, y, rcond=None)
            spread = np.std(y - x @ np.array([p, q, r]))
            print(f"{long.sum()} faults with N >= 100: {name} = {p:.3f} log10 N + {q:.4f} b + {r:.3f} "
                  f"(residual sd {spread:.3f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
