"""The creep statistics of runs that differ only in their integrator settings, side by side.

    python examples/slow/convergence.py LABEL=SUMMARY [LABEL=SUMMARY ...]   > docs/slow/convergence.md

Each summary is `analysis reduce` of one run of examples/slow/convergence.toml (one point); the table
gives its numbers with their 95% intervals (examples/slow/convergence.sh makes them).
"""
import sys

from analysis import summary

NUMBERS = ("creep_share", "taken_over_share", "aseismic_fraction", "fraction_large", "n_events", "mean_tnu")


def main(argv):
    rows = ["| setting | " + " | ".join(NUMBERS) + " |", "|---" * (len(NUMBERS) + 1) + "|"]
    for arg in argv:
        label, path = arg.rsplit("=", 1)
        s = summary.read(path)
        cells = []
        for name in NUMBERS:
            est, lo, hi = s[f"points/numbers/{name}"][0]
            cells.append(f"{est:.4g} [{lo:.4g}, {hi:.4g}]")
        rows.append(f"| {label} | " + " | ".join(cells) + " |")
    print("\n".join(rows))


if __name__ == "__main__":
    main(sys.argv[1:])
