"""Time to the statistics: the wall time until every parameter point has its recorded events, with
and without branching (run.branch), measured on 1 and 2 ranks and projected to many.

    python -m benchmarks.time_to_statistics [--config examples/time_to_statistics/fig1_top.toml]
        [--ranks 1 2] [--seeds 2] [--events 10000] [--project 1 2 16 64 256] [--full-events 200000]
        [--calibrate 2000] [--out benchmarks/results]

1. Calibration, one core, per parameter point of the config: the wall time of one spin-up from
   the random initial state (run.transient events, the same as a task's transient without
   branching), and the cost of a recorded event after it (the mean over `--calibrate` events).
   The fixed cost of a run (start-up, imports, the compiled kernels from numba's cache, the
   catalog) is measured per rank count as the wall time of a run of one event.
2. The model: the runner's schedule replayed with those costs. One counter hands out work in
   order, each rank taking the next item when it is free; without branching the items are the
   tasks (transient + events / seeds each); with branching first the spin-ups, then a barrier
   (every spin-up done), then the tasks (decorrelation + events / seeds each). Its wall time is the
   fixed cost plus the last rank's end: the critical path.
3. Measurement: `python -m ensemble run` (serially on 1 rank, under mpiexec on more) of the config
   with `--seeds` seeds per point sharing `--events` recorded events per point, with and without
   branching, timed from outside; beside the model's prediction for the same run.
4. Projection at the paper's size (`--full-events` recorded per point) to `--project` ranks: for
   each rank count the number of seeds per point (a power of two up to 4 x ranks / points, at least
   one) with the shortest predicted time, with and without branching, and the core-hours it costs.

The projection assumes what the model does: ranks as fast as this machine's cores, each run's fixed
cost as measured here on the largest rank count measured, and the counter's traffic negligible (one
fetch per task). Writes time_to_statistics.{txt,json,png}; the measured runs' catalogs go to a
temporary directory and are deleted. About 30 minutes here with the defaults; nothing else should
share the cores.
"""
import argparse
import heapq
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ensemble.config import load, replace
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list

from .common import Clock, pyplot, save_figure, write_outputs

ROOT = Path(__file__).resolve().parents[1]


# -- the model ------------------------------------------------------------------------------

def schedule(items, ranks, barrier=0):
    """Wall time of items (seconds each, in the order the counter hands them out) on `ranks` ranks
    that each take the next item when free; after the first `barrier` items every rank waits
    until all of them are done (the spin-ups of run.branch)."""
    free = [0.0] * ranks
    heapq.heapify(free)
    end = 0.0
    for k, cost in enumerate(items):
        if k == barrier and barrier:
            end = max(end, max(free))
            free = [end] * ranks
        start = heapq.heappop(free)
        heapq.heappush(free, start + cost)
        end = max(end, start + cost)
    return max(end, max(free))


def work_items(costs, seeds, events, branch, decorrelation):
    """(items, barrier) of a run: costs per point {"spinup": s, "event": s}; `events` recorded per
    point, shared by its `seeds` tasks (task = point * seeds + seed, the runner's order)."""
    per_task = events / seeds
    if not branch:
        return [c["spinup"] + per_task * c["event"] for c in costs for _ in range(seeds)], 0
    spins = [c["spinup"] for c in costs]
    tasks = [(decorrelation + per_task) * c["event"] for c in costs for _ in range(seeds)]
    return spins + tasks, len(spins)


def predict(costs, fixed, ranks, seeds, events, branch, decorrelation):
    """Predicted wall time (s) and core-seconds of a run."""
    items, barrier = work_items(costs, seeds, events, branch, decorrelation)
    return fixed + schedule(items, ranks, barrier), sum(items)


def best_seeds(costs, fixed, ranks, events, branch, decorrelation):
    """(seeds, wall, core seconds) with the shortest predicted wall time over seeds = 1, 2, 4, ...
    up to 4 ranks / points (at least 1): more seeds than that only add transients."""
    top = max(1, 4 * ranks // len(costs))
    options = [2 ** k for k in range(int(np.log2(top)) + 1)]
    results = [(s, *predict(costs, fixed, ranks, s, events, branch, decorrelation)) for s in options]
    return min(results, key=lambda r: r[1])


# -- calibration and measurement ------------------------------------------------------------

def calibrate(cfg, n_events):
    """Per point: {"spinup": wall time of run.transient events from the initial state of its seed 0,
    "event": mean wall time of a recorded event after that}."""
    costs = []
    for task in task_list(replace(cfg, "run", seeds=1)):
        traj = Trajectory(cfg, task)
        traj.advance(1)     # compiled kernels loaded before any timing
        clock = Clock()
        traj.advance(cfg.run.transient - 1)
        spinup = clock.elapsed * cfg.run.transient / max(cfg.run.transient - 1, 1)
        clock = Clock()
        traj.advance(n_events)
        costs.append({"point": task.point, "spinup": spinup, "event": clock.elapsed / n_events})
        print(f"calibrated point {task.point}: spin-up {spinup:.1f} s, {n_events / clock.elapsed:.0f} events/s",
              flush=True)
    return costs


def launch(ranks):
    """The command prefix of a run on `ranks` ranks: serial for one, else the environment's mpiexec."""
    if ranks == 1:
        return [sys.executable]
    mpiexec = Path(sys.executable).parent / "mpiexec"
    return [str(mpiexec) if mpiexec.exists() else (shutil.which("mpiexec") or "mpiexec"), "-n", str(ranks),
            sys.executable]


def timed_run(config, out, ranks, sets):
    """Wall time (s) of `python -m ensemble run` from outside; its catalog is deleted."""
    env = dict(os.environ, OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    env.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache"))
    cmd = launch(ranks) + ["-m", "ensemble", "run", str(config), "-o", str(out), "--force"]
    for s in sets:
        cmd += ["--set", s]
    start = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT, stdin=subprocess.DEVNULL)
    seconds = time.perf_counter() - start
    if res.returncode != 0:
        raise SystemExit(f"error: {' '.join(cmd)} failed ({res.returncode}): {res.stderr.strip()[-500:]}")
    Path(out).unlink(missing_ok=True)
    return seconds


def fixed_cost(config, ranks, scratch):
    """Wall time of a run of one event per task (one point, one seed, no transient) on `ranks` ranks."""
    return timed_run(config, scratch / "fixed.h5", ranks,
                     ["run.events=1", "run.transient=0", "run.seeds=1", "run.branch=false"]
                     + [f"sweep.{key}=[{values[0]!r}]" for key, values in load(config).sweep])


# -- report ---------------------------------------------------------------------------------

def plot(measured, projected, full_events, path, title):
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), squeeze=False)
    ax = axes[0, 0]
    for branch, style in ((False, "C0"), (True, "C1")):
        rows = [m for m in measured if m["branch"] == branch]
        label = "branching" if branch else "independent seeds"
        ax.plot([m["ranks"] for m in rows], [m["measured"] for m in rows], "o", color=style,
                label=f"measured, {label}")
        ax.plot([m["ranks"] for m in rows], [m["model"] for m in rows], "x--", color=style,
                label=f"model, {label}")
    ax.set_xlabel("ranks")
    ax.set_ylabel("wall time (s)")
    ax.set_title(f"measured size ({measured[0]['events']} events per point, {measured[0]['seeds']} seeds)",
                 fontsize=8)
    ax = axes[0, 1]
    for branch, style in ((False, "C0"), (True, "C1")):
        rows = [p for p in projected if p["branch"] == branch]
        ax.loglog([p["ranks"] for p in rows], [p["wall"] / 60 for p in rows], "o-", color=style,
                  label="branching" if branch else "independent seeds")
    ax.axhline(5, color="gray", lw=0.8, ls=":")
    ax.set_xlabel("ranks")
    ax.set_ylabel("wall time (min)")
    ax.set_title(f"model at {full_events:.0e} events per point, best seeds per point", fontsize=8)
    axes[0, 1].legend(fontsize=6)
    save_figure(fig, axes, title, path)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--config", default="examples/time_to_statistics/fig1_top.toml")
    p.add_argument("--ranks", type=int, nargs="+", default=[1, 2], help="rank counts measured")
    p.add_argument("--seeds", type=int, default=2, help="seeds per point of the measured runs")
    p.add_argument("--events", type=int, default=10000, help="recorded events per point of the measured runs")
    p.add_argument("--project", type=int, nargs="+", default=[1, 2, 16, 64, 256], help="rank counts projected")
    p.add_argument("--full-events", type=int, default=200000, help="recorded events per point, projected")
    p.add_argument("--calibrate", type=int, default=2000, help="events timed per point after its spin-up")
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    cfg = load(args.config)
    D = cfg.run.decorrelation
    costs = calibrate(cfg, args.calibrate)
    measured, fixed = [], {}
    with tempfile.TemporaryDirectory(prefix="tts-") as scratch:
        scratch = Path(scratch)
        for ranks in args.ranks:
            fixed[ranks] = fixed_cost(args.config, ranks, scratch)
            print(f"fixed cost on {ranks} rank(s): {fixed[ranks]:.1f} s", flush=True)
            for branch in (False, True):
                sets = [f"run.seeds={args.seeds}", f"run.events={args.events // args.seeds}",
                        f"run.branch={'true' if branch else 'false'}"]
                wall = timed_run(args.config, scratch / "run.h5", ranks, sets)
                model, _ = predict(costs, fixed[ranks], ranks, args.seeds, args.events, branch, D)
                measured.append({"ranks": ranks, "branch": branch, "seeds": args.seeds, "events": args.events,
                                 "measured": wall, "model": model, "ratio": model / wall})
                print(f"{ranks} rank(s), branch {branch}: measured {wall:.1f} s, model {model:.1f} s", flush=True)
    fixed_big = fixed[max(fixed)]
    projected = []
    for ranks in args.project:
        for branch in (False, True):
            seeds, wall, core = best_seeds(costs, fixed_big, ranks, args.full_events, branch, D)
            projected.append({"ranks": ranks, "branch": branch, "seeds": seeds, "wall": wall,
                              "core_hours": core / 3600})
    name = Path(args.config).name
    lines = [f"# python -m benchmarks.time_to_statistics --config {args.config} --ranks "
             f"{' '.join(map(str, args.ranks))} --seeds {args.seeds} --events {args.events}",
             f"# {name}: {len(costs)} points, run.transient {cfg.run.transient}, run.decorrelation {D}, "
             f"{cfg.integrator.method} rtol {cfg.integrator.rtol:g}",
             "", "Calibration (one core):", "| point | spin-up | recorded events/s |", "|---|---|---|"]
    lines += [f"| {c['point']} | {c['spinup']:.1f} s | {1 / c['event']:.0f} |" for c in costs]
    lines += ["", "Fixed cost of a run: " + ", ".join(f"{fixed[r]:.1f} s on {r} rank(s)" for r in fixed),
              "", f"Measured ({args.events} recorded events per point, {args.seeds} seeds per point):",
              "| ranks | branching | measured | model | model / measured |", "|---|---|---|---|---|"]
    lines += [f"| {m['ranks']} | {'yes' if m['branch'] else 'no'} | {m['measured']:.1f} s | {m['model']:.1f} s | "
              f"{m['ratio']:.3f} |" for m in measured]
    lines += ["", f"Projected ({args.full_events} recorded events per point; seeds per point chosen for the "
                  f"shortest time):",
              "| ranks | branching | seeds per point | wall time | core-hours |", "|---|---|---|---|---|"]
    lines += [f"| {q['ranks']} | {'yes' if q['branch'] else 'no'} | {q['seeds']} | {q['wall'] / 60:.1f} min | "
              f"{q['core_hours']:.2f} |" for q in projected]
    write_outputs(args.out, "time_to_statistics",
                  {"config": args.config, "transient": cfg.run.transient, "decorrelation": D, "costs": costs,
                   "fixed": fixed, "measured": measured, "projected": projected,
                   "full_events": args.full_events}, lines)
    plot(measured, projected, args.full_events, Path(args.out) / "time_to_statistics.png",
         f"time to {name}'s statistics")
    return 0


if __name__ == "__main__":
    sys.exit(main())
