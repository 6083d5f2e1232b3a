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

Catalog mode, from runs already done (resumable: the runs are ordinary catalogs, e.g. of
examples/tolerance/run.sh, one per integrator setting; nothing is integrated here):

    python -m benchmarks.statistics --catalogs REF.h5 CAND.h5 [CAND.h5 ...] [--label NAME ...]
                                    [--name catalogs] [--mu-c MU] [--window 10] [--out benchmarks/results]

The first catalog is the reference. Per parameter point (N, l, nu, law and its keys), each task's
committed events give its seed's mu and T nu exactly as a simulated trajectory's do (the catalog's
transient is already excluded), and the same distances, noise floor, table and figure follow, one
set per point: {name}_N{N}_b{b}.{json,txt,png} (other keys that vary across points are added to the
name). A setting is labelled by its tasks' stored [integrator] ("ark4:rtol=1e-3", "rk4:dt=1e-3")
unless --label gives one per catalog, the reference's first. Its events/s is the mean of its tasks'
/tasks/events_per_second (recorded events per second of kernel time, as the run measured it; runs
that shared the machine compare only roughly; NaN until a task finishes). A NAME.h5.partial
catalog (a run not finished) is read up to its committed events; the text output states each
setting's committed and planned event counts. mu_c is the law's (aging: 4) unless --mu-c is given.
A catalog whose points or mu_c / window differ from the reference's is refused (one line naming
the file, exit 2); so is a reference with committed events in fewer than two seeds of a point.
"""
import argparse
import dataclasses
import itertools
import multiprocessing
import sys
import tomllib

import numpy as np

from analysis.recurrence import RecurrenceScanner
from ensemble.store import reader
from ensemble.store.errors import CatalogError
from ensemble.store.schema import KIND_EVENT
from ensemble.config import LAW_KEYS, Integrator, Model
from ensemble.integrators import INTEGRATORS
from ensemble.model import laws
from ensemble.run.trajectory import SimulationError, event_rows

from .common import (Clock, ks_distance, minutes, parse_setting, pyplot, rough_events_per_second, save_figure,
                     trajectory, wasserstein1, write_outputs)

RUNS = ["rk4:dt=1e-3", "ark3:rtol=1e-5", "ark4:rtol=1e-4", "ark4:rtol=1e-5", "ark4:rtol=1e-6",
        "ark5:rtol=1e-5", "exp4:rtol=1e-4", "exp4:rtol=1e-3"]
DISTANCES = {"ks": ks_distance, "w1": wasserstein1}
SAMPLES = ("mu", "tnu")
MAX_SPLITS = 10
# what tells parameter points apart (as analysis.reduce.PARAMS, with the law's name)
POINT_KEYS = ("N", "l", "nu", "law", *LAW_KEYS)
# options of the simulation mode that --catalogs does not use, and the reverse
SIMULATION_ONLY = ("N", "b", "reference", "runs", "seeds", "events", "transient", "seed", "jobs")
CATALOG_ONLY = ("label", "name", "rerun")


class Refused(ValueError):
    """Catalogs that cannot be compared (one line naming the file): exit 2."""


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
    samples = seed_samples([rows], args.N, traj.task.model.nu, args.mu_c, args.window)
    return index, seed_index, {"status": "ok", **samples, "seconds": seconds}


def seed_samples(chunks, N, nu, mu_c, window):
    """One trajectory's recorded rows (dicts of columns t, epicenter, mu, boundary, kind) -> {"mu": the
    magnitudes of its inertial events, "tnu": the local recurrence times T nu of its large events}
    (creep episodes, kind 1, are no events here, as in analysis/reduce.py)."""
    scanner = RecurrenceScanner(N, mu_c, window)
    mu, T = [np.zeros(0)], [np.zeros(0)]
    for rows in chunks:
        keep = rows["kind"] == KIND_EVENT
        chunk = {name: rows[name][keep] for name in ("t", "epicenter", "mu", "boundary")}
        mu.append(chunk["mu"])
        T.append(scanner.feed(chunk["t"], chunk["epicenter"], chunk["mu"], chunk["boundary"])[1])
    return {"mu": np.concatenate(mu), "tnu": np.concatenate(T) * nu}


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


def pooled(per_seed, rate=None):
    """The seeds' samples pooled; events/s the pooled events over the pooled seconds, or `rate`."""
    ok = [r for r in per_seed.values() if r["status"] == "ok"]
    if len(ok) < len(per_seed):
        return {"status": next(r["status"] for r in per_seed.values() if r["status"] != "ok")}
    seconds = sum(r["seconds"] for r in ok)
    out = {s: np.concatenate([r[s] for r in ok]) for s in SAMPLES}
    if not len(out["mu"]):
        return {"status": "no events committed"}
    rate = len(out["mu"]) / seconds if rate is None else rate
    return {"status": "ok", "seconds": seconds, "events_per_second": rate, **out}


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


def plot(rows, floor, path, title, xlabel="events per second (one core)", floor_label="noise floor (reference halves)"):
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    ref = rows[0]
    for ax, key in zip(axes.flat, [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]):
        band = floor[key]
        ax.axhspan(band["min"], band["max"], color="0.85", label=floor_label)
        ax.axhline(band["mean"], color="0.6", lw=1)
        for k, r in enumerate(rows[1:]):
            if r["status"] == "ok" and np.isfinite(r[key]) and np.isfinite(r["events_per_second"]):
                ax.plot(r["events_per_second"], r[key], "o", color=f"C{k}", label=r["setting"])
        if ref["status"] == "ok" and np.isfinite(ref["events_per_second"]):
            ax.axvline(ref["events_per_second"], color="k", ls=":", lw=1, label=f"reference {ref['setting']}")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_ylim(bottom=0)
        ax.set_xlabel(xlabel, fontsize=8)
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
    p.add_argument("--mu-c", type=float, default=None,
                   help="large events: mu >= mu_c (default: the friction law's, aging: 4)")
    p.add_argument("--window", type=int, default=10, help="recurrence: epicenters within this many blocks")
    p.add_argument("--jobs", type=int, default=1, help="processes (each runs whole trajectories)")
    p.add_argument("--out", default="benchmarks/results")
    p.add_argument("--catalogs", nargs="+", metavar="CATALOG",
                   help="catalog mode: the reference's catalog, then the candidates' (NAME.h5 or NAME.h5.partial)")
    p.add_argument("--label", nargs="+", help="catalog mode: one label per catalog, the reference's first "
                                              "(default: from each catalog's [integrator])")
    p.add_argument("--name", default="catalogs", help="catalog mode: output files {name}_N{N}_b{b}.*")
    p.add_argument("--rerun", help="catalog mode: the reference's integrator from another root seed; its "
                                   "halves and its distance from the reference join the noise floor")
    args = p.parse_args(argv)
    mode, other = (SIMULATION_ONLY, CATALOG_ONLY) if args.catalogs else (CATALOG_ONLY, SIMULATION_ONLY)
    stray = [k for k in mode if getattr(args, k) != p.get_default(k)]
    if stray:
        p.error(f"{', '.join('--' + k for k in stray)}: only {'without' if args.catalogs else 'with'} --catalogs")
    if args.catalogs:
        if len(args.catalogs) < 2:
            p.error("--catalogs: a reference and at least one candidate")
        if args.label and len(args.label) != len(args.catalogs):
            p.error(f"--label: one per catalog ({len(args.catalogs)}), got {len(args.label)}")
    else:
        if args.seeds < 2:
            p.error("--seeds must be >= 2 (the noise floor compares halves of the reference seeds)")
        if args.mu_c is None:
            args.mu_c = laws.get(Model().law).scales.mu_c
    return args


def main(argv=None):
    args = parse_args(argv)
    if args.catalogs:
        try:
            return compare_catalogs(args)
        except Refused as err:
            print(f"error: {err}", file=sys.stderr)
            raise SystemExit(2) from None
        except CatalogError as err:
            print(f"error: {err}", file=sys.stderr)
            raise SystemExit(1) from None
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


# -- catalog mode ----------------------------------------------------------------------------

def short(value):
    """A number as a setting label writes it: 1e-3, 2.5e-4, 0.5."""
    if isinstance(value, float) and value and not 1e-2 <= abs(value) < 1e4:
        return np.format_float_scientific(value, trim="-", exp_digits=1)
    return f"{value:g}" if isinstance(value, float) else str(value)


# [integrator] keys only the adaptive methods read (config.Integrator)
ADAPTIVE_ONLY = ("rtol", "atol", "max_step")


def integrator_label(texts):
    """Tasks' stored [integrator] TOML -> a setting label: the method, its step or tolerance
    (rk4: dt; adaptive: rtol), and any other key off its default ("ark4:rtol=1e-3")."""
    defaults = dataclasses.asdict(Integrator())
    labels = []
    for text in dict.fromkeys(t for t in texts if t):
        fields = tomllib.loads(text)
        method = fields.pop("method")
        adaptive = INTEGRATORS[method].adaptive
        main_key = "rtol" if adaptive else "dt"
        unused = () if adaptive else ADAPTIVE_ONLY      # what RK4 ignores, whatever its value
        keys = [main_key] + [k for k, v in fields.items()
                             if k != main_key and k not in unused and v != defaults.get(k)]
        labels.append(f"{method}:" + ",".join(f"{k}={short(fields[k])}" for k in keys))
    return "+".join(labels) or "unknown"


def point_of(tasks, k):
    """Task k's parameter point: ((key, value), ...), NaN as None so that equal points compare equal."""
    values = []
    for key in POINT_KEYS:
        v = tasks[key][k]
        v = str(v) if key == "law" else float(v)
        values.append((key, None if isinstance(v, float) and np.isnan(v) else v))
    return tuple(values)


def read_catalog(path, mu_c, window):
    """One catalog -> its setting: root seed, transient, and per point each task's samples
    (seed_samples, as a simulated trajectory's), events/s, committed and planned events."""
    with reader.Reader(path) as cat:
        tasks = cat.tasks
        config = tomllib.loads(str(cat.attrs["config"]))
        out = {"path": str(path), "label": integrator_label(tasks["integrator"]),
               "root_seed": config["run"]["seed"], "transient": int(cat.attrs["transient"]), "points": {}}
        for k in range(len(tasks["point"])):
            point = point_of(tasks, k)
            c = laws.get(str(tasks["law"][k])).scales.mu_c if mu_c is None else mu_c
            p = out["points"].setdefault(point, {"mu_c": c, "window": window, "per_seed": {}, "rates": [],
                                                 "written": 0, "planned": 0})
            samples = seed_samples(cat.task_events(k), int(tasks["N"][k]), float(tasks["nu"][k]), c, window)
            rate = float(tasks["events_per_second"][k])
            seconds = len(samples["mu"]) / rate if rate > 0 else float("nan")   # NaN: not finished
            p["per_seed"][int(tasks["seed_index"][k])] = {"status": "ok", **samples, "seconds": seconds}
            p["rates"].append(rate)
            p["written"] += int(tasks["events_written"][k])
            p["planned"] += int(cat.per_task)
    return out


def point_text(point):
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in point if v is not None)


def check_against(ref, cand):
    """Refused unless the candidate has the reference's points and their mu_c and window."""
    if set(cand["points"]) != set(ref["points"]):
        extra = [point_text(p) for p in cand["points"] if p not in ref["points"]]
        missing = [point_text(p) for p in ref["points"] if p not in cand["points"]]
        raise Refused(f"{cand['path']}: its points differ from the reference {ref['path']}'s"
                      + (f"; not in the reference: {'; '.join(extra)}" if extra else "")
                      + (f"; missing: {'; '.join(missing)}" if missing else ""))
    for point, p in cand["points"].items():
        r = ref["points"][point]
        if (p["mu_c"], p["window"]) != (r["mu_c"], r["window"]):
            raise Refused(f"{cand['path']}: mu_c = {p['mu_c']:g}, window = {p['window']} at {point_text(point)}; "
                          f"the reference {ref['path']} has {r['mu_c']:g}, {r['window']}")


def point_stem(name, point, points):
    """{name}_N{N}_b{b}, and every other key that differs between the points."""
    values = dict(point)
    keys = ["N"] + (["b"] if values["b"] is not None else [])
    keys += [k for k in POINT_KEYS if k not in keys and len({dict(q)[k] for q in points}) > 1]
    return name + "".join(f"_{k}{short(values[k]) if isinstance(values[k], float) else values[k]}"
                          for k in keys if values[k] is not None)


def with_rerun(floor, ref_seeds, rerun_seeds):
    """The noise floor widened by a rerun of the reference (its integrator, another root seed): its
    own halves, scaled like the reference's, and its full-size distance from the reference."""
    theirs = noise_floor(rerun_seeds)
    direct = distances(pooled(rerun_seeds)["mu"], pooled(ref_seeds)["mu"])
    direct_t = distances(pooled(rerun_seeds)["tnu"], pooled(ref_seeds)["tnu"])
    out = {}
    for key, entry in floor.items():
        name, sample = key.split("_", 1)
        values = entry["splits"] + theirs[key]["splits"] + [(direct if sample == "mu" else direct_t)[name]]
        out[key] = {"splits": values, "min": float(np.min(values)), "mean": float(np.mean(values)),
                    "max": float(np.max(values))}
    return out


def rerun_rows(rows, pools, rerun_seeds):
    """Every setting against the rerun (the reference's integrator from another root seed, the candidates'):
    the reference's own distance from it is the size of the sampling noise in one pair of samples."""
    rerun = pooled(rerun_seeds)
    if rerun["status"] != "ok":
        return []
    large = float(np.mean(rerun["mu"] >= 4))
    return [{**summarize(r["setting"], pool, rerun), "fraction_large_rerun": large}
            for r, pool in zip(rows, pools) if pool["status"] == "ok"]


def rerun_lines(rows):
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    lines = ["against the rerun (first row: the reference; then each candidate):",
             f"  {'setting':26s} {'frac>=4':>8s} {'rerun':>7s} " + " ".join(f"{k:>8s}" for k in keys)]
    for r in rows:
        lines.append(f"  {r['setting']:26s} {r['fraction_large']:8.4f} {r['fraction_large_rerun']:7.4f} "
                     + " ".join(f"{r[k]:8.4f}" for k in keys))
    return lines


def within_noise(rows, floor):
    """Labels of the candidates every distance of which is at most the noise floor's max."""
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    return [r["setting"] for r in rows[1:] if r["status"] == "ok"
            and all(r.get(k, np.inf) <= floor[k]["max"] for k in keys)]


def compare_catalogs(args):
    """Catalog mode: per point, the candidates' distances from the reference; the data per point."""
    settings = [read_catalog(path, args.mu_c, args.window) for path in args.catalogs]
    ref = settings[0]
    rerun = read_catalog(args.rerun, args.mu_c, args.window) if args.rerun else None
    for cand in settings[1:] + ([rerun] if rerun else []):
        check_against(ref, cand)
    for s, label in zip(settings, args.label or [s["label"] for s in settings]):
        s["label"] = label
    results = {}
    for point in ref["points"]:
        with_events = {k: r for k, r in ref["points"][point]["per_seed"].items() if len(r["mu"])}
        if len(with_events) < 2:
            raise Refused(f"{ref['path']}: committed events in {len(with_events)} seed(s) at {point_text(point)}; "
                          "the noise floor needs two")
        pools = [pooled(s["points"][point]["per_seed"], float(np.nanmean(s["points"][point]["rates"]))
                        if np.isfinite(s["points"][point]["rates"]).any() else float("nan")) for s in settings]
        rows = [summarize(ref["label"], pools[0], None)]
        rows += [summarize(s["label"], pool, pools[0]) for s, pool in zip(settings[1:], pools[1:])]
        floor = noise_floor(with_events)
        if rerun:
            floor = with_rerun(floor, with_events, rerun["points"][point]["per_seed"])
        title = f"{point_text(point)}, from catalogs, reference {ref['label']}"
        stem = point_stem(args.name, point, list(ref["points"]))
        inside = within_noise(rows, floor)
        lines = table(rows, floor, title) + catalog_notes(settings + ([rerun] if rerun else []), point)
        against_rerun = []
        if rerun:
            lines.append(f"noise floor: also the halves of the rerun {rerun['path']} (root seed "
                         f"{rerun['root_seed']}) and its distance from the reference")
            against_rerun = rerun_rows(rows, pools, rerun["points"][point]["per_seed"])
            lines += rerun_lines(against_rerun)
        lines.append(f"within the noise (every distance <= the floor's max): {', '.join(inside) or 'none'}")
        data = {"config": vars(args), "point": dict(point), "rows": rows, "noise_floor": floor,
                "within_noise": inside, "against_rerun": against_rerun,
                "catalogs": [{"path": s["path"], "label": s["label"], "root_seed": s["root_seed"],
                              "transient": s["transient"], "events_written": s["points"][point]["written"],
                              "events_planned": s["points"][point]["planned"],
                              "task_events_per_second": s["points"][point]["rates"]} for s in settings]}
        write_outputs(args.out, stem, data, lines)
        plot(rows, floor, f"{args.out}/{stem}.png", title,
             xlabel="events per second (mean over the catalog's tasks, as its run measured)",
             floor_label="noise floor (halves of the reference and its rerun, and their distance)" if rerun
             else "noise floor (reference halves)")
        results[stem] = data
    return results


def catalog_notes(settings, point):
    ref = settings[0]
    lines = ["events/s: the mean of each catalog's /tasks/events_per_second (recorded events per second of "
             "kernel time, as its run measured it; those runs may have shared the machine, so the rates "
             "compare only roughly; nan until a task has finished)",
             "catalogs (events committed / planned at this point, root seed, transient):"]
    for s in settings:
        p = s["points"][point]
        notes = [] if p["written"] == p["planned"] else ["INCOMPLETE"]
        if p["written"] < ref["points"][point]["written"]:
            notes.append("fewer events than the reference: more noise than the floor says")
        if s is not ref and s["root_seed"] == ref["root_seed"]:
            notes.append("the reference's root seed: not an independent sample")
        if s["transient"] != ref["transient"]:
            notes.append("another transient than the reference's")
        lines.append(f"  {s['label']:22s} {p['written']:8d} / {p['planned']:<8d} seed {s['root_seed']:<4d} "
                     f"transient {s['transient']:<6d} {s['path']}" + "".join(f"  [{n}]" for n in notes))
    return lines


if __name__ == "__main__":
    main()
