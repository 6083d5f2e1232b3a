"""Cost per event against the chain length N and against b, by event size; or against the side of a plane.

    python -m benchmarks.cost_scaling [--runs rk4:dt=5e-4] [--Ns 200 400 800 1600 3200 6400]
                                      [--bs 20 30 40 50] [--N-at 800] [--b-at 20] [--events 2000]
                                      [--transient-per-block 1.0] [--out benchmarks/results]
    python -m benchmarks.cost_scaling --plane --runs exp4 --Ns 32 64 128 256 --bs --b-at 40 --events 1000
                                      --budget 600 --transient-per-block 0 --min-transient 300 --name plane_cost

The target ("Speed against error"): the cost of an event grows no faster than the number of
blocks it touches, i.e. it is flat in N for small events. For each setting of `--runs`, each N
of `--Ns` (at b = `--b-at`) and each b of `--bs` (at N = `--N-at`), a chain runs
max(500, transient-per-block x N) events of transient, then `--events` events one kernel call
each, timed one by one (the measured cost of an empty call is subtracted). Per size class
(small mu < 3, mid 3 <= mu < 4, large mu >= 4) it reports the count, microseconds per event,
block-steps per event, blocks that slid per event (D_NSLIP), block-steps per slid block and
microseconds per slid block; overall events/s. Flat "us per slid block" in N means the cost
follows the event, not the chain. The default setting is RK4 at dt = 5e-4, the largest
dt stable at b = 50 (at b = 20, dt = 1e-3 is about twice as fast).
Writes cost_scaling.{json,txt,png}. Default run: about 15-20 min on one core (N = 3200 with its
3200-event transient took 1.5 min under load).

With --plane each N is the side of an N x N plane (model.geometry = "lattice"), and each point also reports the
cost of its one-block events (the quiet interval before an event and the event's own few steps: flat in the
number of blocks is the target) and the fraction of events that slip the whole plane; its events are timed in
cpu seconds of the process (not wall: less touched by other work on the machine). --budget stops a point's
timed events after that many seconds of its process's cpu time (a plane's whole-plane event costs in
proportion to its area); --name names the output files.
"""
import argparse
import time

import numpy as np

from ensemble.model.workspace import D_BLOCK_STEPS, D_NSLIP, D_SLIP
from ensemble.run.trajectory import SimulationError

from .common import (Clock, minutes, parse_setting, pyplot, rough_events_per_second, save_figure, trajectory,
                     write_outputs)

CLASSES = {"small": (-np.inf, 3.0), "mid": (3.0, 4.0), "large": (4.0, np.inf)}
QUANTITIES = {"us_per_event": "us per event", "us_per_slid_block": "us per slid block",
              "block_steps_per_slid_block": "block-steps per slid block"}


def call_overhead(traj, repeats=200, timer=time.perf_counter):
    """Median seconds of a kernel call that runs no event (Python and dispatch cost)."""
    times = []
    for _ in range(repeats):
        start = timer()
        traj.advance(0)
        times.append(timer() - start)
    return float(np.median(times))


def measure_point(setting, N, b, events, transient, seed, M=None, budget=np.inf):
    """Per-event seconds and diagnostics of `events` events after the transient (fewer if `budget` cpu seconds
    run out first); a summary dict. M: a plane of N x M blocks, its events timed in cpu seconds of the process
    (wall seconds on the chain)."""
    timer = time.perf_counter if M is None else time.process_time
    traj = trajectory(N, b, setting, 0, 1, seed, M=M)
    point = {"setting": setting.label, "N": N, "M": M or 1, "b": b, "transient": transient}
    try:
        traj.advance(transient)
        overhead = call_overhead(traj, timer=timer)
        seconds = []
        diag = []
        clock, cpu = Clock(), time.process_time()
        while len(seconds) < events and time.process_time() - cpu < budget:
            start = timer()
            diag.append(traj.advance(1)[2][0])
            seconds.append(timer() - start)
        wall = clock.elapsed
    except SimulationError as err:
        return {**point, "status": f"failed: {err}"}
    diag = np.array(diag)
    seconds = np.maximum(np.array(seconds) - overhead, 0.0)
    mu = np.log10(diag[:, D_SLIP])
    single = diag[:, D_NSLIP] == 1
    point.update(status="ok", events=len(seconds), events_per_second=len(seconds) / wall,
                 call_overhead_us=overhead * 1e6, us_per_event=1e6 * seconds.mean(),
                 ns_per_block_step=1e9 * seconds.sum() / diag[:, D_BLOCK_STEPS].sum(),
                 us_per_one_block_event=1e6 * seconds[single].mean() if single.any() else None,
                 one_block_events=int(single.sum()),
                 whole_fraction=float(np.mean(diag[:, D_NSLIP] == N * (M or 1))))
    for name, (lo, hi) in CLASSES.items():
        sel = (mu >= lo) & (mu < hi)
        steps, slid, sec = diag[sel, D_BLOCK_STEPS], diag[sel, D_NSLIP], seconds[sel]
        point[name] = {"count": int(sel.sum())} if not sel.any() else {
            "count": int(sel.sum()), "us_per_event": 1e6 * sec.mean(), "block_steps_per_event": steps.mean(),
            "slid_blocks_per_event": slid.mean(), "block_steps_per_slid_block": steps.sum() / slid.sum(),
            "us_per_slid_block": 1e6 * sec.sum() / slid.sum()}
    return point


def table(points):
    lines = ["cost per event by size class (small mu < 3, mid 3..4, large mu >= 4); times after "
             "subtracting the empty-call overhead",
             f"{'setting':16s} {'N':>5s} {'b':>4s} {'events/s':>9s} {'ns/bstep':>8s} {'class':>6s} {'count':>6s} "
             f"{'us/event':>10s} {'bsteps/ev':>10s} {'slid/ev':>8s} {'bsteps/slid':>11s} {'us/slid':>8s}"]
    for p in points:
        head = f"{p['setting']:16s} {p['N']:5d} {p['b']:4g}" if p.get("M", 1) == 1 else \
            f"{p['setting']:10s} {p['N']:4d}x{p['M']:<4d} {p['b']:4g}"
        if p["status"] != "ok":
            lines.append(f"{head} {p['status'][:100]}")
            continue
        for k, name in enumerate(CLASSES):
            c = p[name]
            lead = f"{head} {p['events_per_second']:9.1f} {p['ns_per_block_step']:8.0f}" if k == 0 else " " * 45
            lines.append(f"{lead} {name:>6s} {c['count']:6d} " + (
                f"{c['us_per_event']:10.1f} {c['block_steps_per_event']:10.3g} {c['slid_blocks_per_event']:8.1f} "
                f"{c['block_steps_per_slid_block']:11.1f} {c['us_per_slid_block']:8.2f}" if c["count"] else ""))
    lines += ["", "one-block events (the quiet interval before them and their own steps) and whole-plane events",
              f"{'setting':16s} {'N':>5s} {'M':>5s} {'b':>4s} {'events':>7s} {'1-block':>8s} {'us/1-block':>10s} "
              f"{'whole':>6s}"]
    for p in points:
        if p["status"] == "ok":
            single = "" if p["us_per_one_block_event"] is None else f"{p['us_per_one_block_event']:10.1f}"
            lines.append(f"{p['setting']:16s} {p['N']:5d} {p.get('M', 1):5d} {p['b']:4g} {p['events']:7d} "
                         f"{p['one_block_events']:8d} {single:>10s} {p['whole_fraction']:6.3f}")
    return lines


def plot(points, sweeps, path):
    plt = pyplot()
    fig, axes = plt.subplots(len(sweeps), len(QUANTITIES), figsize=(4 * len(QUANTITIES), 3.4 * len(sweeps)),
                             squeeze=False)
    for row, (var, other, sel) in enumerate(sweeps):
        for col, (key, label) in enumerate(QUANTITIES.items()):
            ax = axes[row, col]
            for k, setting in enumerate(dict.fromkeys(p["setting"] for p in points)):
                for name, marker in zip(CLASSES, "o^s"):
                    pts = [p for p in sel if p["setting"] == setting and p["status"] == "ok"
                           and p[name]["count"]]
                    if pts:
                        ax.plot([p[var] for p in pts], [p[name][key] for p in pts], marker + "-", color=f"C{k}",
                                label=f"{setting} {name}", ms=4)
            ax.set_xscale("log" if var == "N" else "linear")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(plt.NullFormatter())
            ax.yaxis.set_minor_formatter(plt.NullFormatter())
            ax.set_xlabel(f"{var} ({other})", fontsize=8)
            ax.set_ylabel(label, fontsize=8)
            ax.tick_params(labelsize=7)
    save_figure(fig, axes, "cost per event by size class (flat in N = cost follows the event)", path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", nargs="+", default=["ark4:rtol=1e-5", "rk4:dt=5e-4"], help="kernel settings")
    p.add_argument("--Ns", type=int, nargs="*", default=[200, 400, 800, 1600, 3200, 6400], help="N sweep")
    p.add_argument("--b-at", type=float, default=20.0, help="b of the N sweep")
    p.add_argument("--bs", type=float, nargs="*", default=[20.0, 30.0, 40.0, 50.0], help="b sweep")
    p.add_argument("--N-at", type=int, default=800, help="N of the b sweep")
    p.add_argument("--events", type=int, default=2000, help="timed events per point")
    p.add_argument("--transient-per-block", type=float, default=1.0,
                   help="transient events per block (at least 500)")
    p.add_argument("--min-transient", type=int, default=500)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="benchmarks/results")
    p.add_argument("--plane", action="store_true", help="each N is the side of an N x N plane")
    p.add_argument("--budget", type=float, default=np.inf, help="cpu seconds of timed events per point at most")
    p.add_argument("--name", default="cost_scaling", help="the output files' name")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    settings = [parse_setting(text) for text in args.runs]
    grid = [(N, args.b_at) for N in args.Ns] + [(args.N_at, b) for b in args.bs if (args.N_at, b) not in
                                                 [(N, args.b_at) for N in args.Ns]]
    transient = {N: max(args.min_transient, int(args.transient_per_block * N)) for N, _ in grid}
    guess = sum((transient[N] + args.events) / rough_events_per_second(s) for s in settings for N, _ in grid)
    print(f"{len(settings)} settings x {len(grid)} points (N, b): roughly {minutes(guess)} "
          f"(a guess from the rate at N = 800; large N may be slower)", flush=True)
    points = []
    clock = Clock()
    for s in settings:
        for N, b in grid:
            points.append(measure_point(s, N, b, args.events, transient[N], args.seed, M=N if args.plane else None,
                                        budget=args.budget))
            p = points[-1]
            print(f"  {s.label} N={N} b={b:g}: " + (f"{p['events_per_second']:.1f} events/s"
                  if p["status"] == "ok" else p["status"]) + f" ({minutes(clock.elapsed)} elapsed)", flush=True)
    along = f"side of an N x N plane, b = {args.b_at:g}" if args.plane else f"b = {args.b_at:g}"
    sweeps = [("N", along, [p for p in points if p["b"] == args.b_at and p["N"] in args.Ns]),
              ("b", f"N = {args.N_at}", [p for p in points if p["N"] == args.N_at and p["b"] in args.bs])]
    sweeps = [sw for sw in sweeps if sw[2]]
    data = {"config": vars(args), "points": points, "wall_seconds": clock.elapsed}
    write_outputs(args.out, args.name, data, table(points))
    plot(points, sweeps, f"{args.out}/{args.name}.png")
    return data


if __name__ == "__main__":
    main()
