"""How long the transient lasts: when the event statistics of a chain started from the default
random state (run.init_stress) stop drifting.

    python -m benchmarks.transient CATALOG [CATALOG ...] [--window 1000] [--out benchmarks/results]

The catalogs must record from the first event (run.transient = 0), several seeds per point. Per
point, the events of every seed are cut into windows of `window` events; window k pools window k
of every seed. Against the late-time distribution (the second half of every seed, pooled):

- the Kolmogorov-Smirnov distance of the window's magnitudes, beside its noise floor: the 99th
  percentile of the distance of late windows (window-long stretches at random places of the second
  halves, one per seed, pooled) from the same late-time distribution. Events within a stretch are
  correlated (the chain's large-event cycles), so the floor comes from stretches, not from events
  drawn one by one, which would put it about 1.5 times too low;
- the fraction of large events (mu >= the law's mu_c), beside the late value and the standard
  deviation of a late window's.

The transient ends after the leading windows whose KS distance is above the floor: the first window
below it starts the stationary part (by chance a stationary window exceeds the floor 1% of the time,
which would lengthen the measured transient by one window). The stress profile is not measured:
catalogs keep only the last state of each task.
Writes transient.txt, transient.json and transient.png.
"""
import argparse
import json
import os

import numpy as np

from ensemble.store import reader
from ensemble.store.schema import KIND_EVENT
from ensemble.model import laws

FLOOR_DRAWS = 400


def ks(a, b_sorted):
    """Two-sample KS distance between a and the sorted sample b_sorted."""
    a = np.sort(a)
    grid = np.concatenate([a, b_sorted])
    fa = np.searchsorted(a, grid, side="right") / len(a)
    fb = np.searchsorted(b_sorted, grid, side="right") / len(b_sorted)
    return float(np.max(np.abs(fa - fb)))


def point_curves(mu_by_seed, window, mu_c, rng):
    """Per window: KS to the late distribution, its floor, fraction large, mean mu; and the end."""
    n = min(len(m) for m in mu_by_seed)
    late = np.sort(np.concatenate([m[n // 2:n] for m in mu_by_seed]))
    k = n // window
    def late_window():
        return np.concatenate([m[s:s + window] for m, s in
                               zip(mu_by_seed, rng.integers(n // 2, n - window + 1, len(mu_by_seed)))])
    draws = [late_window() for _ in range(FLOOR_DRAWS)]
    floor = np.percentile([ks(d, late) for d in draws], 99)
    spread = float(np.std([np.mean(d >= mu_c) for d in draws], ddof=1))
    rows = []
    for w in range(k):
        sample = np.concatenate([m[w * window:(w + 1) * window] for m in mu_by_seed])
        rows.append((ks(sample, late), np.mean(sample >= mu_c), sample.mean()))
    rows = np.array(rows)
    end = 0
    while end < k and rows[end, 0] > floor:
        end += 1
    return {"ks": rows[:, 0], "fraction_large": rows[:, 1], "mean_mu": rows[:, 2], "floor": floor,
            "late_fraction_large": float(np.mean(late >= mu_c)), "late_mean_mu": float(late.mean()),
            "sd_fraction_large": spread,
            "end_window": end, "end_events": end * window, "events_per_seed": n}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("catalogs", nargs="+")
    p.add_argument("--window", type=int, default=1000)
    p.add_argument("--out", default="benchmarks/results")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    results = []
    for path in args.catalogs:
        events, tasks, attrs = reader.read(path)
        if int(attrs["transient"]) != 0:
            raise SystemExit(f"error: {path}: run.transient is {int(attrs['transient'])}; "
                             "the measurement needs the events from the first one (run.transient = 0)")
        for point in np.unique(tasks["point"]):
            rows = np.flatnonzero(tasks["point"] == point)
            law = str(tasks["law"][rows[0]])
            mu_c = laws.get(law).scales.mu_c
            # events, not creep
            mu = [events["mu"][(events["task"] == g) & (events["kind"] == KIND_EVENT)] for g in rows]
            keys = [k for k in laws.get(law).keys]
            label = f"N = {int(tasks['N'][rows[0]])}, " + ", ".join(f"{k} = {tasks[k][rows[0]]:g}" for k in keys)
            curves = point_curves(mu, args.window, mu_c, rng)
            curves.update(label=label, catalog=os.path.basename(path), seeds=len(rows), N=int(tasks["N"][rows[0]]))
            results.append(curves)
    os.makedirs(args.out, exist_ok=True)
    lines = [f"# python -m benchmarks.transient {' '.join(os.path.basename(c) for c in args.catalogs)} "
             f"--window {args.window}",
             "| point | seeds | events per seed | KS floor (99%) | transient ends after | per block | "
             "large fraction: first window / late |", "|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['label']} | {r['seeds']} | {r['events_per_seed']} | {r['floor']:.4f} | "
                     f"{r['end_events']} events | {r['end_events'] / r['N']:.2f} | "
                     f"{r['fraction_large'][0]:.3f} / {r['late_fraction_large']:.3f} "
                     f"(sd of a late window {r['sd_fraction_large']:.3f}) |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    with open(os.path.join(args.out, "transient.txt"), "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "transient.json"), "w") as f:
        json.dump([{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r.items()} for r in results],
                  f, indent=1)
    _figure(results, args.window, os.path.join(args.out, "transient.png"))


def _figure(results, window, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True)
    for r, color in zip(results, plt.rcParams["axes.prop_cycle"].by_key()["color"]):
        x = (np.arange(len(r["ks"])) + 0.5) * window
        a.plot(x, r["ks"], color=color, lw=1.2, label=r["label"])
        a.axhline(r["floor"], color=color, ls=":", lw=0.8)
        a.axvline(r["end_events"], color=color, ls="--", lw=0.8)
        b.plot(x, r["fraction_large"], color=color, lw=1.2)
        b.axhline(r["late_fraction_large"], color=color, ls=":", lw=0.8)
    a.set(yscale="log", ylabel="KS distance of a window's mu\nto the late distribution",
          title="from the random start (dotted: floor, late value; dashed: end of transient)")
    a.legend(fontsize=8)
    b.set(xlabel="events since the start, per seed", ylabel="fraction of large events")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
