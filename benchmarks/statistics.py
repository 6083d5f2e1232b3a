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
import multiprocessing
import sys

from ensemble.config import Model
from ensemble.model import laws
from ensemble.run.trajectory import SimulationError, event_rows
from ensemble.store.errors import CatalogError

from .common import Clock, minutes, parse_setting, rough_events_per_second, trajectory, write_outputs
# the measure (statistics_distances.py) and the catalog mode (statistics_catalogs.py); the names tests and
# readers reach through this module stay importable from it (F401: imported for them, not used here)
from .statistics_catalogs import Refused, compare_catalogs, integrator_label, short  # noqa: F401
from .statistics_distances import (DISTANCES, SAMPLES, distances, noise_floor, plot, pooled, rerun_rows,  # noqa: F401
                                   seed_samples, summarize, table, with_rerun, within_noise)

RUNS = ["rk4:dt=1e-3", "ark3:rtol=1e-5", "ark4:rtol=1e-4", "ark4:rtol=1e-5", "ark4:rtol=1e-6",
        "ark5:rtol=1e-5", "exp4:rtol=1e-4", "exp4:rtol=1e-3"]
# options of the simulation mode that --catalogs does not use, and the reverse
SIMULATION_ONLY = ("N", "b", "reference", "runs", "seeds", "events", "transient", "seed", "jobs")
CATALOG_ONLY = ("label", "name", "rerun")


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


if __name__ == "__main__":
    main()
