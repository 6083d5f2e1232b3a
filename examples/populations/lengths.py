"""Where a single fault's large events lie, by its length (docs/populations.md):

    python examples/populations/lengths.py runs/populations/lengths.h5 > docs/populations/lengths.md

One row per task of the catalog (examples/populations/lengths.toml): N, b, the inertial events per unit of
loading (T nu), the 50th, 90th and 99th percentiles of mu, and the fraction of events with mu >= 4. Then the
least-squares line of the median mu on log10 N over the faults whose every event ruptures the whole fault
(p99 - p50 below 0.3): mu = slope log10 N + intercept.
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
            yield (float(cat.tasks["N"][k]), float(cat.tasks["b"][k]), (len(mu) - 1) / span,
                   *np.percentile(mu, [50, 90, 99]), float(np.mean(mu >= 4)))


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    table = np.array(list(rows(argv[0])))
    print(f"| N | b | events per {NU_UNITS} | mu: p50 | p90 | p99 | fraction mu >= 4 |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for N, b, rate, p50, p90, p99, large in table:
        print(f"| {N:.0f} | {b:g} | {rate:.3g} | {p50:.2f} | {p90:.2f} | {p99:.2f} | {large:.3f} |")
    whole = table[:, 5] - table[:, 3] < 0.3
    print()
    for b in np.unique(table[whole, 1]):
        sel = whole & (table[:, 1] == b)
        slope, intercept = np.polyfit(np.log10(table[sel, 0]), table[sel, 3], 1)
        print(f"b = {b:g}: faults ruptured whole in every event: N = {', '.join(f'{n:.0f}' for n in table[sel, 0])}; "
              f"median mu = {slope:.3f} log10 N + {intercept:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
