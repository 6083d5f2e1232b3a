"""Hard cases at full size: each method without per-case tuning, health and energy balance.

    python -m benchmarks.hard_cases [--runs rk4 ark3] [--cases b100 a30 c1e2 c1e6 nu1e-6 nu1e-10 N6400 long]
                                    [--N 800] [--N-large 6400] [--transient 300] [--events 800]
                                    [--max-seconds 30] [--long-t 1e15] [--long-nu auto]
                                    [--long-max-seconds 150] [--late-events 200] [--out benchmarks/results]

The issue's cases (tests/test_hard_cases.py runs them at small sizes): b = 100 (very fast slip),
a = 30 (strong velocity strengthening), c = 1e2 and 1e6, nu = 1e-6 and 1e-10, all at N = `--N`;
N = `--N-large` at b = 20; and `long`, a genuine run at N = `--N` until the absolute time passes
`--long-t`, then `--late-events` more. Every other parameter is the paper's (Model defaults).

Settings (`--runs`): a bare method name runs it untuned: "rk4" at the step the case needs
(2e-4 for b = 100, whose slip reaches v ~ 7000 beyond RK4's limit dt * v < 2.785 at dt = 1e-3;
else 1e-3), an adaptive method ("ark3", ...) at its default tolerances. "rk4:dt=5e-4" or
"ark3:rtol=1e-5" fix the options for every case instead.

A run integrates `--transient` events (not reported), then `--events` events, each phase
within `--max-seconds` of wall time (the long run: `--long-max-seconds`); a run cut short
reports the events it has. Per run: events recorded, events/s, max and median relative energy
residual (events.relative_energy_residual), failure (the runner's SimulationError), non-finite
values, events with zero slip and onsets that do not increase, v_max, fraction of large events
(mu >= `--mu-c`), final absolute time. The long run also compares the events before and after
`--long-t` (mean mu, fraction large, KS distance of mu).

`--long-nu auto` first measures, with a short run of each method at nu = 1e-8 (the paper's
setting), how many events reaching `--long-t` takes and how long; if any method needs more than
`--long-max-seconds`, the long run uses nu = 1e-10 (recurrence ~100x longer). Measured at
N = 800: ~2.4e5 events at nu = 1e-8 (35 min with rk4, 2 h with ark3), ~2.4e3 at nu = 1e-10.
Writes hard_cases.{json,txt}. Default run: about 10 min on one core (from rates measured at N = 800;
the a = 30 and N = 6400 runs end at the time caps; an estimate is printed at the start).
"""
import argparse
import dataclasses

import numpy as np

from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import relative_energy_residual
from ensemble.model.workspace import D_ENERGY_SCALE, D_RESIDUAL, D_SLIP, D_T_SPREAD, D_VMAX, NDIAG
from ensemble.run.trajectory import SimulationError, Trajectory
from ensemble.sweep import task_list

from .common import Clock, ks_distance, minutes, parse_setting, rough_events_per_second, write_outputs

# name: (description, model changes from the paper's setting at N = --N, RK4 step it needs)
CASES = {
    "b100": ("very fast slip b = 100", {"b": 100.0}, 2e-4),
    "a30": ("strong strengthening a = 30", {"a": 30.0}, 1e-3),
    "c1e2": ("c = 1e2", {"c": 1e2}, 1e-3),
    "c1e6": ("c = 1e6", {"c": 1e6}, 1e-3),
    "nu1e-6": ("nu = 1e-6", {"nu": 1e-6}, 1e-3),
    "nu1e-10": ("nu = 1e-10", {"nu": 1e-10}, 1e-3),
    "N6400": ("large chain (--N-large)", {}, 1e-3),
    "long": ("long run past --long-t", {}, 1e-3),
}
PROBE_NU = 1e-8      # the paper's loading rate, tried first for the long run
FALLBACK_NU = 1e-10
CHUNK = 20           # events per kernel call (the clocks are checked between calls)


def integrator(setting, rk4_dt):
    """The setting's Integrator: a bare "rk4" at the case's step, a bare adaptive name at its defaults."""
    if setting.name == "rk4" and "dt" not in setting.kwargs:
        return Integrator(method="rk4", dt=rk4_dt, **setting.kwargs)
    return setting.integrator()


def make_trajectory(model, integ, seed):
    cfg = Config(model=model, run=Run(seed=seed), integrator=integ)
    return Trajectory(cfg, task_list(cfg)[0])


def advance(traj, n_events, seconds, until_t=None, out=None):
    """Events in chunks until n_events (or the clock passes until_t, if given) or `seconds` run out.

    Appends (onset times, diagnostics) of every kernel call to `out` (so they survive a
    SimulationError, which propagates) and returns the wall seconds.
    """
    out = [] if out is None else out
    clock = Clock(seconds)
    done = 0
    while not clock.expired:
        if until_t is None:
            n = min(CHUNK, n_events - done)
            if n <= 0:
                break
        elif traj.clock[0] + traj.clock[1] > until_t:
            break
        else:
            n = CHUNK
        t, _, diag = traj.advance(n)
        out.append((t, diag))
        done += n
    return clock.elapsed


def joined(out, ncols):
    """(onset times, diagnostics) of the calls collected by `advance`."""
    return (np.concatenate([np.empty(0)] + [t for t, _ in out]),
            np.concatenate([np.empty((0, ncols))] + [d for _, d in out]))


def summary(t, diag, seconds, mu_c):
    """Health and statistics of recorded events (zero-slip events are counted, not measured)."""
    slip = diag[:, D_SLIP]
    ok = slip > 0
    residual = relative_energy_residual(diag[ok, D_RESIDUAL], diag[ok, D_ENERGY_SCALE])
    mu = np.log10(slip[ok])
    out = {"events": len(t), "events_per_second": len(t) / seconds if seconds > 0 else None,
           # (t_spread is NaN for an event whose sliding zone never grew beyond its onset's: not a failure)
           "nonfinite": int((~np.isfinite(np.delete(diag, D_T_SPREAD, axis=1))).sum() + (~np.isfinite(t)).sum()
                            + (~np.isfinite(residual)).sum()),
           "zero_slip": int((~ok).sum()), "non_increasing_onsets": int((np.diff(t) <= 0).sum()),
           "t_first": float(t[0]) if len(t) else None, "t_last": float(t[-1]) if len(t) else None}
    if ok.any():
        out.update(residual_max=float(np.nanmax(residual)), residual_median=float(np.nanmedian(residual)),
                   v_max=float(np.nanmax(diag[ok, D_VMAX])), mu_mean=float(np.mean(mu)),
                   fraction_large=float(np.mean(mu >= mu_c)))
    return out


def measure(name, setting, model, rk4_dt, args, until_t=None):
    """One run: transient, then the recorded events; a dict for the table."""
    integ = integrator(setting, rk4_dt)
    point = {"case": name, "setting": setting.label, "method": integ.method, "dt": integ.dt,
             "rtol": integ.rtol, "atol": integ.atol, **dataclasses.asdict(model)}
    traj = make_trajectory(model, integ, args.seed)
    recorded = []
    seconds = 0.0
    try:
        advance(traj, args.transient, args.max_seconds)
        point["transient"] = traj.done
        if until_t is None:
            seconds = advance(traj, args.events, args.max_seconds, out=recorded)
        else:
            seconds = advance(traj, 0, args.long_max_seconds, until_t, out=recorded)
            if traj.clock[0] + traj.clock[1] > until_t:
                seconds += advance(traj, args.late_events, args.max_seconds, out=recorded)
        point["status"] = "ok"
    except SimulationError as err:
        point["status"] = f"failed: {err}"
    t, diag = joined(recorded, NDIAG)
    point["final_time"] = float(traj.clock[0] + traj.clock[1])
    point.update(summary(t, diag, seconds, args.mu_c))
    wanted = args.events if until_t is None else args.late_events
    if point["status"] == "ok" and (until_t is None and point["events"] < wanted
                                   or until_t is not None and point["final_time"] <= until_t):
        point["status"] = "time limit"
    if until_t is not None and point["events"]:
        before, after = t <= until_t, t > until_t
        mu = np.log10(np.where(diag[:, D_SLIP] > 0, diag[:, D_SLIP], np.nan))
        halves = {}
        for label, sel in (("before", before), ("after", after)):
            m = mu[sel & np.isfinite(mu)]
            halves[label] = {"events": int(sel.sum()), "mu_mean": float(m.mean()) if len(m) else None,
                             "fraction_large": float(np.mean(m >= args.mu_c)) if len(m) else None}
        ma, mb = mu[before & np.isfinite(mu)], mu[after & np.isfinite(mu)]
        halves["ks_mu"] = ks_distance(ma, mb) if len(ma) and len(mb) else None
        point["long"] = {"t_target": until_t, **halves}
    return point


def probe_long(settings, args):
    """Events and time to pass --long-t at nu = 1e-8, from a short run of each setting."""
    model = Model(N=args.N, nu=PROBE_NU)
    rows = []
    for s in settings:
        integ = integrator(s, 1e-3)
        traj = make_trajectory(model, integ, args.seed)
        row = {"setting": s.label, "nu": PROBE_NU}
        measured = []
        try:
            advance(traj, args.probe_events, args.probe_seconds)
            seconds = advance(traj, args.probe_events, args.probe_seconds, out=measured)
        except SimulationError as err:
            rows.append({**row, "status": f"failed: {err}"})
            continue
        t, _ = joined(measured, NDIAG)
        interval = (t[-1] - t[0]) / (len(t) - 1)
        rate = len(t) / seconds
        events = traj.done + (args.long_t - t[-1]) / interval
        rows.append({**row, "status": "ok", "mean_interval": interval, "events_per_second": rate,
                     "events_to_target": events, "seconds_to_target": events / rate})
        print(f"  probe {s.label} at nu = {PROBE_NU:g}: one event per {interval:.2e} time units, "
              f"{rate:.0f} events/s: t > {args.long_t:g} takes ~{events:.2g} events, "
              f"~{minutes(rows[-1]['seconds_to_target'])}", flush=True)
    return rows


def table(points, probe, long_nu):
    lines = ["hard cases: events after a transient; residual = relative energy residual; zero = events with "
             "zero slip; ties = non-increasing onsets",
             f"{'case':8s} {'setting':12s} {'N':>5s} {'status':>10s} {'events':>6s} {'ev/s':>7s} {'res max':>8s} "
             f"{'res med':>8s} {'nonfin':>6s} {'zero':>4s} {'ties':>4s} {'v_max':>7s} {'large':>6s} {'t_end':>8s}"]
    for p in points:
        status = p["status"] if p["status"] in ("ok", "time limit") else "FAILED"
        def num(key, fmt):
            return format(p[key], fmt) if p.get(key) is not None else "-"
        lines.append(f"{p['case']:8s} {p['setting'][:12]:12s} {p['N']:5d} {status:>10s} {p['events']:6d} "
                     f"{num('events_per_second', '7.1f')} {num('residual_max', '8.1e')} "
                     f"{num('residual_median', '8.1e')} {p['nonfinite']:6d} {p['zero_slip']:4d} "
                     f"{p['non_increasing_onsets']:4d} {num('v_max', '7.0f')} {num('fraction_large', '6.3f')} "
                     f"{p['final_time']:8.2e}")
    for p in points:
        if p["status"] not in ("ok", "time limit"):
            lines.append(f"  {p['case']} {p['setting']}: {p['status']}")
    for row in probe:
        lines.append(f"long run probe {row['setting']} at nu = {row['nu']:g}: " + (
            f"~{row['events_to_target']:.2g} events, ~{minutes(row['seconds_to_target'])} to pass the target"
            if row["status"] == "ok" else row["status"]))
    for p in points:
        if "long" in p:
            lg = p["long"]
            def part(h):
                return (f"{h['events']} events, mean mu {h['mu_mean']:.3f}, large {h['fraction_large']:.3f}"
                        if h["mu_mean"] is not None else f"{h['events']} events")
            ks = f", KS distance of mu {lg['ks_mu']:.3f}" if lg["ks_mu"] is not None else ""
            lines.append(f"long run {p['setting']} (nu = {long_nu:g}): t <= {lg['t_target']:g}: "
                         f"{part(lg['before'])}; after: {part(lg['after'])}{ks}")
    return lines


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", nargs="+", default=["rk4", "ark4"],
                   help="settings; a bare name is untuned (rk4 at the case's dt, adaptive at defaults)")
    p.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    p.add_argument("--N", type=int, default=800, help="blocks of every case but N6400")
    p.add_argument("--N-large", type=int, default=6400, help="blocks of the N6400 case")
    p.add_argument("--transient", type=int, default=300, help="events discarded first")
    p.add_argument("--events", type=int, default=800, help="events recorded per run")
    p.add_argument("--max-seconds", type=float, default=30.0, help="wall-time cap of each phase of a run")
    p.add_argument("--long-t", type=float, default=1e15, help="absolute time the long run must pass")
    p.add_argument("--long-nu", default="auto", help="nu of the long run, or auto (probe 1e-8, else 1e-10)")
    p.add_argument("--long-max-seconds", type=float, default=150.0, help="wall-time cap of the long run")
    p.add_argument("--late-events", type=int, default=200, help="events of the long run after --long-t")
    p.add_argument("--probe-events", type=int, default=200, help="events (twice: transient, measured) of the probe")
    p.add_argument("--probe-seconds", type=float, default=15.0, help="wall-time cap of each probe phase")
    p.add_argument("--mu-c", type=float, default=4.0, help="large-event magnitude")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="benchmarks/results")
    return p.parse_args(argv)


def estimate(settings, args):
    """(rough, cap) seconds of the whole run, from benchmarks.common's calibrated rates."""
    rough = cap = 0.0
    for s in settings:
        for name in args.cases:
            _, _, rk4_dt = CASES[name]
            rate = rough_events_per_second(parse_setting(f"rk4:dt={rk4_dt:g}") if s.label == "rk4" else s)
            if name == "N6400":
                rate /= 2     # a guess: its transient events span the whole chain
            if name == "long":
                rough += 2 * args.probe_seconds if args.long_nu == "auto" else 0.0
                rough += min(args.long_max_seconds, 2500 / rate) + args.late_events / rate
                cap += 2 * args.probe_seconds + args.long_max_seconds + 2 * args.max_seconds
            else:
                rough += min(args.max_seconds, args.transient / rate) + min(args.max_seconds, args.events / rate)
                cap += 2 * args.max_seconds
    return rough, cap


def main(argv=None):
    args = parse_args(argv)
    settings = [parse_setting(text) for text in args.runs]
    rough, cap = estimate(settings, args)
    print(f"{len(settings)} settings x {len(args.cases)} cases: roughly {minutes(rough)}, at most {minutes(cap)} "
          f"(time caps; rates guessed from N = 800, b = 20)", flush=True)
    clock = Clock()
    points, probe = [], []
    long_nu = None
    for name in args.cases:
        desc, changes, rk4_dt = CASES[name]
        until_t = None
        if name == "long":
            if args.long_nu == "auto":
                probe = probe_long(settings, args)
                fits = all(r["status"] == "ok" and r["seconds_to_target"] <= args.long_max_seconds for r in probe)
                long_nu = PROBE_NU if fits else FALLBACK_NU
                print(f"  long run at nu = {long_nu:g}" + ("" if fits else
                      f" (nu = {PROBE_NU:g} needs more than --long-max-seconds {args.long_max_seconds:g})"),
                      flush=True)
            else:
                long_nu = float(args.long_nu)
            changes = {"nu": long_nu}
            until_t = args.long_t
        model = Model(N=args.N_large if name == "N6400" else args.N, **changes)
        for s in settings:
            p = measure(name, s, model, rk4_dt, args, until_t)
            points.append(p)
            rate = f"{p['events_per_second']:.1f} events/s" if p.get("events_per_second") else "-"
            print(f"  {name} ({desc}) {s.label}: {p['status'][:200]}, {p['events']} events, {rate}, "
                  f"t_end {p['final_time']:.2e} ({minutes(clock.elapsed)} elapsed)", flush=True)
    data = {"config": vars(args), "long_nu": long_nu, "probe": probe, "points": points,
            "wall_seconds": clock.elapsed}
    write_outputs(args.out, "hard_cases", data, table(points, probe, long_nu))
    return data


if __name__ == "__main__":
    main()
