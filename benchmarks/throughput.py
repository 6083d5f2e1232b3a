"""Events per second of a developed chain, one core.

    python benchmarks/throughput.py [--N 800] [--b 20] [--dt 1e-3] [--method NAME]
                                    [--rtol 1e-5] [--transient 1000] [--events 2000]
                                    [--law carlson-langer --alpha 2 --sigma 0.01 | --law slip --a 0] [--per-row]

Runs the transient (not timed, includes compilation), then times `events`
recorded events and prints events/s (wall clock, and per second of the process's cpu time), cost per block-step,
the magnitude range and the largest relative energy residual. Below the block stiffness the rows are inertial events and
creep episodes: it prints the rate of each, the event statistics of the inertial events alone, and the
energy balance of the timed stretch of the run, events and creep together (ensemble/energy.py: a creep
episode has no residual of its own).
"""
import argparse
import time

import numpy as np

from ensemble import energy
from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import relative_energy_residual
from ensemble.integrators import INTEGRATORS
from ensemble.model.workspace import (D_BLOCK_STEPS, D_DURATION, D_ENERGY_SCALE, D_KIND, D_NSLIP, D_RESIDUAL, D_SLIP,
                                      D_STEPS, KIND_CREEP, KIND_EVENT)
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800)
    p.add_argument("--b", type=float, default=20.0)
    p.add_argument("--a", type=float, default=0.0)
    p.add_argument("--law", default="aging", help="model.law (docs/laws.md)")
    p.add_argument("--alpha", type=float, default=2.0, help="carlson-langer's alpha")
    p.add_argument("--sigma", type=float, default=0.01, help="carlson-langer's sigma")
    p.add_argument("--nu", type=float, default=Model().nu)
    p.add_argument("--dt", type=float, default=1e-3)
    p.add_argument("--method", default="rk4",
                   help=f"one of {', '.join(INTEGRATORS)} (the registry, ensemble/model/methods.py)")
    p.add_argument("--rtol", type=float, default=Integrator().rtol,
                   help="tolerance of the adaptive methods (default: the config default)")
    p.add_argument("--transient", type=int, default=1000)
    p.add_argument("--events", type=int, default=2000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--per-row", action="store_true",
                   help="time each row alone (one kernel call per row, ~1e-5 s more each) and print the time "
                        "per creep episode and per inertial event: a creep row is charged the work until it is "
                        "reported, an event row the work from its onset")
    args = p.parse_args()
    keys = dict(alpha=args.alpha, sigma=args.sigma) if args.law == "carlson-langer" else dict(a=args.a, b=args.b)
    cfg = Config(model=Model(N=args.N, nu=args.nu, law=args.law, **keys),
                 run=Run(events=args.events, transient=args.transient, seed=args.seed),
                 integrator=Integrator(method=args.method, dt=args.dt, rtol=args.rtol))
    traj = Trajectory(cfg, task_list(cfg)[0])
    traj.advance(args.transient)
    before = (traj.state()[0], traj.clock.sum(), traj.ws.episodes_in_flight())
    start, cpu = time.perf_counter(), time.process_time()
    if args.per_row:
        rows, seconds = [], np.empty(args.events)
        for k in range(args.events):
            t0 = time.perf_counter()
            rows.append(traj.advance(1))
            seconds[k] = time.perf_counter() - t0
        t, _, diag = (np.concatenate(column) for column in zip(*rows))
    else:
        t, _, diag = traj.advance(args.events)
    elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    balance = energy.balance(before, (traj.state()[0], traj.clock.sum(), traj.ws.episodes_in_flight()), t, diag,
                             cfg.model)
    kind = diag[:, D_KIND]
    block_steps = diag[:, D_BLOCK_STEPS].sum()      # (creep steps count their creeping blocks alike)
    creep = diag[diag[:, D_KIND] == KIND_CREEP]
    diag = diag[diag[:, D_KIND] == KIND_EVENT]      # the event statistics below: inertial events alone
    mu = np.log10(diag[:, D_SLIP])
    residual = relative_energy_residual(diag[:, D_RESIDUAL], diag[:, D_ENERGY_SCALE])
    how = f"dt={args.dt}" if args.method == "rk4" else f"rtol={args.rtol:g}"
    point = " ".join(f"{k}={v:g}" for k, v in keys.items())
    print(f"N={args.N} {args.law} {point} {args.method} {how}: {args.events / elapsed:.1f} events/s "
          f"({args.events} events in {elapsed:.1f} s after {args.transient} transient; "
          f"{args.events / max(cpu, 1e-9):.1f} events per cpu-second)")
    if len(creep):
        print(f"  rows: {len(diag)} inertial events ({len(diag) / elapsed:.1f}/s) and {len(creep)} creep episodes "
              f"({len(creep) / elapsed:.1f}/s; median slip {np.median(creep[:, D_SLIP]):.3g}, median duration "
              f"{np.median(creep[:, D_DURATION]):.3g}, {creep[:, D_BLOCK_STEPS].mean():.0f} block-steps each); "
              f"aseismic slip fraction {creep[:, D_SLIP].sum() / (creep[:, D_SLIP].sum() + diag[:, D_SLIP].sum()):.2e}")
        print(f"  energy balance of the run, events and creep: "
              f"residual {abs(balance.residual / balance.load_work):.1e} "
              f"of the driver's work (friction work of the creep episodes {balance.creep_work:.3g}, of the events "
              f"{balance.friction_work - balance.creep_work:.3g}, c-free frame)")
    if args.per_row:
        for name, which in (("inertial event", KIND_EVENT), ("creep episode", KIND_CREEP)):
            if np.any(kind == which):
                print(f"  per {name}: {seconds[kind == which].mean() * 1e3:.3g} ms (median "
                      f"{np.median(seconds[kind == which]) * 1e3:.3g} ms), {seconds[kind == which].sum():.1f} s in all")
    print(f"  {diag[:, D_STEPS].mean():.0f} steps and {diag[:, D_BLOCK_STEPS].mean():.0f} block-steps per event, "
          f"{elapsed / block_steps * 1e9:.0f} ns per block-step")
    print(f"  mu in [{mu.min():.2f}, {mu.max():.2f}], fraction mu >= 4: {np.mean(mu >= 4):.3f}, "
          f"fraction of events slipping >= 50 blocks: {np.mean(diag[:, D_NSLIP] >= 50):.3f}, "
          f"max relative energy residual{' of an inertial event' if len(creep) else ''} {residual.max():.1e}")


if __name__ == "__main__":
    main()
