"""Single-event work-precision: relative error of slip and slip profile against wall time and work.

    python -m benchmarks.work_precision [--N 800] [--b 20 50] [--runs SETTING ...] [--target 1e-6]
                                        [--max-seconds 120] [--out benchmarks/results]

For each b, from fixed pre-event states of a developed chain (the next small event, mu < 3, and
the next large one, mu >= 4, after `--transient` events), integrates the same event with every
setting of `--runs` (syntax in benchmarks/common.py):

- kernel integrators (`rk4:dt=...`, `ark3:rtol=...`, any other name in the registry): only
  the sliding blocks, located stick and onset;
- `numpy-rk4:dt=...`: full-chain numpy RK4, sticks and starts applied at step ends;
- `scipy:method=LSODA|BDF|Radau,rtol=...[,atol=...]`: solve_ivp on all 3N unknowns with sticks
  and starts located as terminal ODE events (limits in benchmarks/baselines.py).

Errors are measured against `--reference` (default: kernel RK4 at a quarter of the smallest RK4
dt of the runs). A run that fails (e.g. RK4 beyond its stability limit: b = 50 needs
dt <= 5e-4) is recorded as "failed"; a baseline run over `--max-seconds` as "timeout".
The cost of each method at error `--target` is interpolated log-log between its measured points
and the speed-up of the kernel's methods over the baselines is the ratio of those costs.
Writes work_precision_N{N}_b{b}.{json,txt,png} per b; the figure has the errors against wall time
(top row) and against block right-hand-side evaluations (bottom row).
Default run: about 5-10 min (mostly the baselines; at N = 800 the slowest, scipy BDF on the large
event, takes ~40 s; each baseline run is capped by --max-seconds).
"""
import argparse

import numpy as np

from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import advance_to_onset, check, run_event
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list

from .baselines import BASELINES, Timeout, run_baseline
from .common import STAGES, cost_at_error, minutes, parse_setting, pyplot, save_figure, write_outputs

RUNS = (["rk4:dt=2e-3", "rk4:dt=1e-3", "rk4:dt=5e-4", "rk4:dt=2.5e-4"]
        + [f"ark3:rtol=1e-{k}" for k in range(4, 9)]
        + [f"ark4:rtol=1e-{k}" for k in range(3, 9)]
        + [f"ark5:rtol=1e-{k}" for k in range(3, 9)]
        + [f"exp4:rtol=1e-{k}" for k in range(2, 9)]
        + ["numpy-rk4:dt=1e-3", "numpy-rk4:dt=5e-4"]
        + [f"scipy:method=LSODA,rtol=1e-{k}" for k in (4, 6, 8)] + ["scipy:method=BDF,rtol=1e-6"])
METRICS = ("slip_error", "profile_error")
# what a ratio of costs means when a cost is only a bound ('bound': every run beat the target, the
# cheapest one's time is an upper bound on the cost at the target)
RATIO_IS = {("interpolated", "interpolated"): "=", ("interpolated", "bound"): ">=",
            ("bound", "interpolated"): "<=", ("bound", "bound"): "?"}


# event classes by magnitude: label -> [lowest mu, highest mu)
SIZES = {"small": (-np.inf, 3.0), "large": (4.0, np.inf)}


def pre_event_states(model, transient, seed=0, sizes=SIZES, max_events=50_000):
    """{label: (force, psi, epicenter, mu)} at the onset of the next event of each size class
    (default: small, mu < 3, and large, mu >= 4); SystemExit if one has not come in max_events."""
    cfg = Config(model=model, run=Run(events=1, transient=transient, seed=seed),
                 integrator=Integrator(method="rk4", dt=5e-4))
    traj = Trajectory(cfg, task_list(cfg)[0])
    traj.advance(transient)
    found = {}
    for _ in range(max_events):
        if len(found) == len(sizes):
            break
        force, psi = traj.state()
        _, _, diag = traj.advance(1)
        mu = np.log10(diag[0, 1])
        label = next((k for k, (lo, hi) in sizes.items() if lo <= mu < hi), None)
        if label and label not in found:
            epicenter, _, f, p = advance_to_onset(force, psi, model)
            f[epicenter] = model.b * p[epicenter]
            found[label] = (f, p, epicenter, mu)
    missing = [f"{k} ({lo:g} <= mu < {hi:g})" for k, (lo, hi) in sizes.items() if k not in found]
    if missing:
        raise SystemExit(f"no event of size class {', '.join(missing)} in {max_events} events after the transient")
    return found


def kernel_event(f, p, epicenter, model, integrator, min_seconds=0.1):
    """(EventResult, wall seconds) of one event: the fastest of >= 3 repeats lasting >= min_seconds
    in all (events take down to 0.05 ms); the first call compiles and is not timed. The time is the
    event kernel's alone, as in a run (run_event's set-up of the O(N) schedule is not counted)."""
    ev = check(run_event(f, p, epicenter, model, integrator))
    times = []
    while len(times) < 3 or sum(times) < min_seconds:
        times.append(run_event(f, p, epicenter, model, integrator).seconds)
    return ev, min(times)


def measure(setting, f, p, epicenter, model, max_seconds):
    """(profile, seconds, block RHS evaluations, block-steps, status) of one setting on one event."""
    try:
        if setting.is_kernel:
            ev, wall = kernel_event(f, p, epicenter, model, setting.integrator())
            stages = STAGES.get(setting.name)
            return ev.profile, wall, stages and stages * ev.block_steps, ev.block_steps, "ok"
        profile, wall, work = run_baseline(setting, f, p, epicenter, model, max_seconds)
        return profile, wall, work, None, "ok"
    except Timeout:
        return None, None, None, None, "timeout"
    except RuntimeError as err:
        return None, None, None, None, f"failed: {err}"


def curve(setting):
    """Points of one curve share the method and its non-numeric options (e.g. scipy's method)."""
    return " ".join([setting.name] + [str(v) for _, v in setting.params if isinstance(v, str)])


def run_b(args, b, settings, reference):
    model = Model(N=args.N, b=b)
    rows = []
    for label, (f, psi, epicenter, mu) in pre_event_states(model, args.transient, args.seed).items():
        ref = check(run_event(f, psi, epicenter, model, reference.integrator()))
        for s in settings:
            profile, wall, work, block_steps, status = measure(s, f, psi, epicenter, model, args.max_seconds)
            row = {"b": b, "event": label, "mu": mu, "n_slipped": int(np.sum(ref.profile > 0)),
                   "setting": s.label, "curve": curve(s), "kernel": s.is_kernel, "status": status,
                   "seconds": wall, "block_rhs": work, "block_steps": block_steps,
                   "slip_error": None, "profile_error": None}
            if profile is not None:
                row["slip_error"] = abs(profile.sum() - ref.slip) / ref.slip
                row["profile_error"] = np.linalg.norm(profile - ref.profile) / np.linalg.norm(ref.profile)
            rows.append(row)
            print(f"b={b:g} {label} mu={mu:.2f} {s.label}: " + (
                f"slip error {row['slip_error']:.1e}, profile error {row['profile_error']:.1e}, {wall:.3f} s"
                if status == "ok" else status), flush=True)
    return rows


def speedups(rows, target):
    """Cost of every curve at the target error and the ratios baseline / kernel, per event and metric."""
    costs, ratios = [], []
    for event in dict.fromkeys(r["event"] for r in rows):
        for metric in METRICS:
            ok = [r for r in rows if r["event"] == event and r["status"] == "ok"]
            here = {}
            for c in dict.fromkeys(r["curve"] for r in ok):
                pts = [r for r in ok if r["curve"] == c]
                seconds, how = cost_at_error([r[metric] for r in pts], [r["seconds"] for r in pts], target)
                here[c] = (seconds, how, pts[0]["kernel"])
                costs.append({"event": event, "metric": metric, "curve": c, "seconds": seconds, "how": how})
            for base, (tb, hb, kb) in here.items():
                for kern, (tk, hk, kk) in here.items():
                    if not kb and kk and tb and tk:
                        ratios.append({"event": event, "metric": metric, "baseline": base, "kernel": kern,
                                       "ratio": tb / tk, "ratio_is": RATIO_IS[hb, hk],
                                       "baseline_how": hb, "kernel_how": hk})
    return costs, ratios


def table(rows, costs, ratios, title, target):
    lines = [f"work-precision, single events, {title}",
             f"{'event':6s} {'mu':>5s} {'setting':34s} {'slip err':>9s} {'prof err':>9s} {'seconds':>9s} "
             f"{'block RHS':>10s}"]
    for r in rows:
        if r["status"] == "ok":
            rhs = f"{r['block_rhs']:10.3g}" if r["block_rhs"] else f"{'?':>10s}"
            lines.append(f"{r['event']:6s} {r['mu']:5.2f} {r['setting']:34s} {r['slip_error']:9.1e} "
                         f"{r['profile_error']:9.1e} {r['seconds']:9.4f} {rhs}")
        else:
            lines.append(f"{r['event']:6s} {r['mu']:5.2f} {r['setting']:34s} {r['status'][:60]}")
    lines.append(f"\nwall time at relative error {target:g} (interpolated log-log; 'bound': every run "
                 f"was more accurate, cheapest shown)")
    for c in costs:
        sec = f"{c['seconds']:.4g} s" if c["seconds"] else "-"
        lines.append(f"  {c['event']:6s} {c['metric']:14s} {c['curve']:16s} {sec:>12s} ({c['how']})")
    lines.append(f"\nspeed-up of the kernel at equal error {target:g} (baseline seconds / kernel seconds; "
                 f"'>=' a lower bound, '<=' an upper bound, '?' both costs are bounds)")
    for q in ratios:
        note = "" if q["ratio_is"] == "=" else f"  (baseline {q['baseline_how']}, kernel {q['kernel_how']})"
        lines.append(f"  {q['event']:6s} {q['metric']:14s} {q['kernel']:6s} vs {q['baseline']:16s} "
                     f"{q['ratio_is']:>2s} {q['ratio']:9.3g}x{note}")
    return lines


def plot(rows, path, title, target):
    plt = pyplot()
    events = list(dict.fromkeys(r["event"] for r in rows))
    panels = [(e, m) for e in events for m in METRICS]
    fig, axes = plt.subplots(2, len(panels), figsize=(3.6 * len(panels), 6.5), squeeze=False)
    curves = list(dict.fromkeys(r["curve"] for r in rows))
    for col, (event, metric) in enumerate(panels):
        for row, xkey, xlabel in ((0, "seconds", "wall time [s]"), (1, "block_rhs", "block RHS evaluations")):
            ax = axes[row, col]
            for k, c in enumerate(curves):
                pts = [r for r in rows if r["event"] == event and r["curve"] == c and r["status"] == "ok"
                       and r[xkey]]
                if pts:
                    ax.loglog([r[xkey] for r in pts], [max(r[metric], 1e-17) for r in pts], "o-",
                              color=f"C{k}", label=c, ms=4)
            ax.axhline(target, color="0.6", ls=":", lw=1)
            ax.set_xlabel(xlabel, fontsize=8)
            ax.set_ylabel(f"relative {metric.replace('_', ' ')}", fontsize=8)
            mu = next(r["mu"] for r in rows if r["event"] == event)
            ax.set_title(f"{event} event (mu = {mu:.2f})", fontsize=8)
            ax.tick_params(labelsize=7)
    save_figure(fig, axes, f"work-precision, single events, {title}", path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800, help="blocks")
    p.add_argument("--b", type=float, nargs="+", default=[20.0, 50.0], help="one figure and table per b")
    p.add_argument("--transient", type=int, default=300, help="events before the pre-event states are taken")
    p.add_argument("--seed", type=int, default=0, help="root seed of the developed chain")
    p.add_argument("--runs", nargs="+", default=RUNS, help="settings to measure (see benchmarks/common.py)")
    p.add_argument("--reference", default=None, help="kernel setting for the reference solution "
                   "(default: rk4 at a quarter of the smallest rk4 dt of --runs, or 6.25e-5)")
    p.add_argument("--target", type=float, default=1e-6, help="relative error at which speed-ups are compared")
    p.add_argument("--max-seconds", type=float, default=120.0, help="wall-time cap of one baseline run")
    p.add_argument("--out", default="benchmarks/results")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    settings = [parse_setting(text, BASELINES) for text in args.runs]
    rk4_dts = [s.kwargs.get("dt", 1e-3) for s in settings if s.name == "rk4"] or [2.5e-4]
    reference = parse_setting(args.reference or f"rk4:dt={min(rk4_dts) / 4:g}")
    baselines = sum(not s.is_kernel for s in settings)
    print(f"{len(settings)} settings x 2 events x {len(args.b)} b; the {baselines} baseline runs per event "
          f"take up to {args.max_seconds:g} s each: at most about "
          f"{minutes(2 * len(args.b) * baselines * args.max_seconds)} in all (reference {reference.label})",
          flush=True)
    for b in args.b:
        rows = run_b(args, b, settings, reference)
        costs, ratios = speedups(rows, args.target)
        title = f"N = {args.N}, b = {b:g}, reference {reference.label}"
        stem = f"work_precision_N{args.N}_b{b:g}"
        data = {"config": {**vars(args), "b": b, "reference": reference.label}, "rows": rows,
                "cost_at_target": costs, "speedups": ratios}
        write_outputs(args.out, stem, data, table(rows, costs, ratios, title, args.target))
        plot(rows, f"{args.out}/{stem}.png", title, args.target)


if __name__ == "__main__":
    main()
