"""Statistical error against speed: distances of event statistics from a tight reference.

    python -m benchmarks.statistics [--N 800] [--b 20] [--reference rk4:dt=2.5e-4]
                                    [--runs rk4:dt=1e-3 ark3:rtol=1e-5 ...] [--seeds 4]
                                    [--events 3000] [--transient 1000] [--jobs 1] [--out benchmarks/results]

Every setting (the reference and each of `--runs`) integrates `--seeds` trajectories of
`--transient` + `--events` events and pools the recorded events over its seeds: the magnitudes
mu = log10(slip) and the local recurrence times T nu of large events (analysis.recurrence: mu >=
`--mu-c`, next large event with epicenter within `--window` blocks). For each candidate it reports
the two-sample Kolmogorov-Smirnov distance and the 1-Wasserstein distance to the reference, of mu
and of T nu, and its recorded events/s (transient excluded).

Noise floor: the same distances between two halves of the reference's seeds, over every balanced
split (at most 10), scaled by sqrt((1/n + 1/n) / (1/n_A + 1/n_B)) to the sample sizes of a
candidate-reference pair with as many events as the reference (the sampling noise of both distances
falls like that with the number of independent seeds). A candidate within the band is
indistinguishable from the reference at this sample size. With 4 seeds there are only 3 splits,
and they share seeds, so the band (their min to max) understates the spread of the noise: a
candidate up to about twice the floor's mean is not clearly different (measured at N = 100: an
independent rerun of the reference itself landed at 1.1-1.5x the mean). The candidates start from the same
initial states as each other but from a different root seed (`--seed` + 1) than the reference,
so that a candidate and the reference are independent samples, as the halves are.
Writes statistics_N{N}_b{b}.{json,txt,png}; the figure has the distances against events/s with the
noise floor as a band. Default run (N = 800, b = 20): about 25 min on one core, half with --jobs 2.
"""
import argparse
import itertools
import multiprocessing

import numpy as np

from analysis.recurrence import RecurrenceScanner
from ensemble.model.workspace import D_SLIP
from ensemble.runner import SimulationError, event_rows

from .common import (Clock, ks_distance, minutes, parse_setting, pyplot, rough_events_per_second, save_figure,
                     trajectory, wasserstein1, write_outputs)

RUNS = ["rk4:dt=1e-3", "ark3:rtol=1e-5", "ark4:rtol=1e-4", "ark4:rtol=1e-5", "ark4:rtol=1e-6",
        "ark5:rtol=1e-5"]
DISTANCES = {"ks": ks_distance, "w1": wasserstein1}
SAMPLES = ("mu", "tnu")
MAX_SPLITS = 10


def run_seed(job):
    """One trajectory of one setting: its recorded magnitudes, T nu and timing (a picklable job)."""
    index, setting, seed_index, root_seed, args = job
    traj = trajectory(args.N, args.b, setting, seed_index, args.seeds, root_seed)
    try:
        traj.advance(args.transient)
        clock = Clock()
        t, epicenter, diag = traj.advance(args.events)
        seconds = clock.elapsed
    except SimulationError as err:
        return index, seed_index, {"status": f"failed: {err}"}
    rows = event_rows(traj.task, t, epicenter, diag)
    _, T, _ = RecurrenceScanner(args.N, args.mu_c, args.window).feed(t, epicenter, rows["mu"], rows["boundary"])
    return index, seed_index, {"status": "ok", "mu": np.log10(diag[:, D_SLIP]),
                                       "tnu": T * traj.task.model.nu, "seconds": seconds}


def distances(x, y):
    """{name: distance} of two samples (NaN if either is empty)."""
    return {name: (f(x, y) if len(x) and len(y) else float("nan")) for name, f in DISTANCES.items()}


def noise_floor(per_seed):
    """Distances between halves of the reference seeds, scaled to two samples of the full size."""
    seeds = sorted(per_seed)
    splits = [s for s in itertools.combinations(seeds, len(seeds) // 2) if seeds[0] in s][:MAX_SPLITS]
    floor = {}
    for sample in SAMPLES:
        values = {name: [] for name in DISTANCES}
        for half in splits:
            a = np.concatenate([per_seed[k][sample] for k in half])
            b = np.concatenate([per_seed[k][sample] for k in seeds if k not in half])
            scale = np.sqrt((2 / (len(a) + len(b))) / (1 / len(a) + 1 / len(b))) if len(a) and len(b) else 1.0
            for name, d in distances(a, b).items():
                values[name].append(d * scale)
        for name, v in values.items():
            floor[f"{name}_{sample}"] = {"splits": v, "min": float(np.min(v)), "mean": float(np.mean(v)),
                                         "max": float(np.max(v))}
    return floor


def pooled(per_seed):
    ok = [r for r in per_seed.values() if r["status"] == "ok"]
    if len(ok) < len(per_seed):
        return {"status": next(r["status"] for r in per_seed.values() if r["status"] != "ok")}
    seconds = sum(r["seconds"] for r in ok)
    out = {s: np.concatenate([r[s] for r in ok]) for s in SAMPLES}
    return {"status": "ok", "seconds": seconds, "events_per_second": len(out["mu"]) / seconds, **out}


def summarize(label, pool, ref):
    row = {"setting": label, "status": pool["status"]}
    if pool["status"] == "ok":
        row.update(events=len(pool["mu"]), recurrences=len(pool["tnu"]), seconds=pool["seconds"],
                   events_per_second=pool["events_per_second"], fraction_large=float(np.mean(pool["mu"] >= 4)),
                   mean_tnu=float(np.mean(pool["tnu"])) if len(pool["tnu"]) else None)
        if ref is not None:
            for sample in SAMPLES:
                for name, d in distances(pool[sample], ref[sample]).items():
                    row[f"{name}_{sample}"] = d
    return row


def table(rows, floor, title):
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    lines = [f"statistical error against speed, {title}",
             f"{'setting':22s} {'events/s':>9s} {'events':>7s} {'T count':>7s} {'frac>=4':>7s} "
             + " ".join(f"{k:>8s}" for k in keys)]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"{r['setting']:22s} {r['status'][:90]}")
            continue
        lines.append(f"{r['setting']:22s} {r['events_per_second']:9.1f} {r['events']:7d} {r['recurrences']:7d} "
                     f"{r['fraction_large']:7.3f} " + " ".join(f"{r.get(k, float('nan')):8.4f}" for k in keys))
    lines.append(f"{'noise floor (mean)':22s} {'':9s} {'':7s} {'':7s} {'':7s} "
                 + " ".join(f"{floor[k]['mean']:8.4f}" for k in keys))
    lines.append(f"{'noise floor (max)':22s} {'':9s} {'':7s} {'':7s} {'':7s} "
                 + " ".join(f"{floor[k]['max']:8.4f}" for k in keys))
    lines.append("first row: the reference (distances not applicable); noise floor: halves of its seeds, "
                 "scaled to full-size samples")
    return lines


def plot(rows, floor, path, title):
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    ref = rows[0]
    for ax, key in zip(axes.flat, [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]):
        band = floor[key]
        ax.axhspan(band["min"], band["max"], color="0.85", label="noise floor (reference halves)")
        ax.axhline(band["mean"], color="0.6", lw=1)
        for k, r in enumerate(rows[1:]):
            if r["status"] == "ok" and np.isfinite(r[key]):
                ax.plot(r["events_per_second"], r[key], "o", color=f"C{k}", label=r["setting"])
        if ref["status"] == "ok":
            ax.axvline(ref["events_per_second"], color="k", ls=":", lw=1, label=f"reference {ref['setting']}")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_ylim(bottom=0)
        ax.set_xlabel("events per second (one core)", fontsize=8)
        name, sample = key.split("_")
        ax.set_ylabel(f"{'KS' if name == 'ks' else 'Wasserstein-1'} distance of "
                      f"{'mu' if sample == 'mu' else 'T nu'}", fontsize=8)
        ax.tick_params(labelsize=7)
    save_figure(fig, axes, f"statistical error against speed, {title}", path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800, help="blocks")
    p.add_argument("--b", type=float, default=20.0)
    p.add_argument("--reference", default="rk4:dt=2.5e-4", help="kernel setting of the reference")
    p.add_argument("--runs", nargs="+", default=RUNS, help="candidate kernel settings")
    p.add_argument("--seeds", type=int, default=4, help="trajectories per setting (>= 2: halves give the floor)")
    p.add_argument("--events", type=int, default=3000, help="recorded events per trajectory")
    p.add_argument("--transient", type=int, default=1000, help="discarded events per trajectory")
    p.add_argument("--seed", type=int, default=0, help="root seed of the reference; candidates use seed + 1")
    p.add_argument("--mu-c", type=float, default=4.0, help="large events: mu >= mu_c")
    p.add_argument("--window", type=int, default=10, help="recurrence: epicenters within this many blocks")
    p.add_argument("--jobs", type=int, default=1, help="processes (each runs whole trajectories)")
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    if args.seeds < 2:
        p.error("--seeds must be >= 2 (the noise floor compares halves of the reference seeds)")
    return args


def main(argv=None):
    args = parse_args(argv)
    reference = parse_setting(args.reference)
    settings = [reference] + [parse_setting(text) for text in args.runs]
    jobs = [(i, s, k, args.seed + (i > 0), args) for i, s in enumerate(settings) for k in range(args.seeds)]
    guess = sum((args.transient + args.events) / rough_events_per_second(s) for _, s, *_ in jobs)
    print(f"{len(settings)} settings x {args.seeds} seeds x ({args.transient} + {args.events}) events: "
          f"roughly {minutes(guess / args.jobs)} with {args.jobs} process(es)", flush=True)
    results = [{} for _ in settings]   # per setting: {seed index: result}
    clock = Clock()
    if args.jobs > 1:
        with multiprocessing.get_context("spawn").Pool(args.jobs) as pool:
            stream = pool.imap_unordered(run_seed, jobs)
            collect(stream, settings, results, len(jobs), clock)
    else:
        collect(map(run_seed, jobs), settings, results, len(jobs), clock)
    ref_pool = pooled(results[0])
    if ref_pool["status"] != "ok":
        raise RuntimeError(f"reference {reference.label}: {ref_pool['status']}")
    rows = [summarize(reference.label, ref_pool, None)]
    rows += [summarize(s.label, pooled(r), ref_pool) for s, r in zip(settings[1:], results[1:])]
    floor = noise_floor(results[0])
    title = (f"N = {args.N}, b = {args.b:g}, {args.seeds} seeds x {args.events} events "
             f"(after {args.transient}), reference {reference.label}")
    stem = f"statistics_N{args.N}_b{args.b:g}"
    data = {"config": vars(args), "rows": rows, "noise_floor": floor, "wall_seconds": clock.elapsed}
    write_outputs(args.out, stem, data, table(rows, floor, title))
    plot(rows, floor, f"{args.out}/{stem}.png", title)
    return data


def collect(stream, settings, results, total, clock):
    for done, (index, seed_index, result) in enumerate(stream, 1):
        results[index][seed_index] = result
        label = settings[index].label
        left = clock.elapsed / done * (total - done)
        print(f"  {label} seed {seed_index}: {result['status'][:80]} ({done}/{total} done, "
              f"{minutes(clock.elapsed)} elapsed, about {minutes(left)} left)", flush=True)


if __name__ == "__main__":
    main()
