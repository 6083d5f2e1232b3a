"""Single-event work-precision: relative slip error against wall time and work.

    python benchmarks/work_precision.py [--N 800] [--b 20] [--out benchmarks/results]

From fixed pre-event states of a developed chain (the next small event, mu < 3, and the next large
one, mu >= 4), integrates the same event with

- the kernel's fixed-step RK4 (located stick and onset) over a range of dt,
- the kernel's adaptive IMEX ARK3(2), ARK4(3) and ARK5(4) over a range of rtol (the "dt" column
  holds rtol), and
- a straightforward full-array numpy RK4 (every block every step, stick by clamping v at the end of
  a step), the baseline a first implementation would be,

and measures the relative error of the event's total slip and of its slip profile against the
kernel at a much smaller dt, the wall time, and the work (right-hand-side evaluations per block:
stages times accepted block-steps; rejected and cut steps are not counted).
Writes a JSON table and a work-precision diagram.
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import advance_to_onset, check, run_event
from ensemble.runner import Trajectory
from ensemble.tasks import task_list

STAGES = {"ark3": 4, "ark4": 6, "ark5": 8}   # adaptive methods and their stages per step


def pre_event_states(model, transient, seed=0):
    """(label, force, psi, epicenter) of the next small (mu < 3) and large (mu >= 4) event."""
    cfg = Config(model=model, run=Run(events=1, transient=transient, seed=seed),
                 integrator=Integrator(dt=5e-4))
    traj = Trajectory(cfg, task_list(cfg)[0])
    traj.advance(transient)
    found = {}
    while len(found) < 2:
        force, psi = traj.ws.force.copy(), traj.ws.psi.copy()
        _, _, diag = traj.advance(1)
        mu = np.log10(diag[0, 1])
        label = "small" if mu < 3 else "large" if mu >= 4 else None
        if label and label not in found:
            epicenter, _, f, p = advance_to_onset(force, psi, model)
            f[epicenter] = model.b * p[epicenter]
            found[label] = (f, p, epicenter, mu)
    return found


def kernel_event(f, p, epicenter, model, integrator, repeat=3):
    """The event and its best wall time of `repeat` runs (the machine may be shared)."""
    run_event(f, p, epicenter, model, integrator)          # compile / warm caches
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        ev = check(run_event(f, p, epicenter, model, integrator))
        best = min(best, time.perf_counter() - start)
    return ev, best


def numpy_rk4_event(f, p, epicenter, model, dt, max_steps=10**7):
    """Full-chain RK4 in numpy on (slip y, v, psi), c-free frame; clamps v at step ends."""
    n = len(f)
    l2, nu, a, b = model.l ** 2, model.nu, model.a, model.b

    def lap(y):
        out = np.empty_like(y)
        out[1:-1] = y[2:] - 2 * y[1:-1] + y[:-2]
        out[0] = y[1] - y[0]
        out[-1] = y[-2] - y[-1]
        return out

    def rates(t, y, v, psi, moving):
        vp = np.maximum(v, 0.0)
        acc = f + nu * t - y + l2 * lap(y) - a * np.log1p(vp) - b * psi
        return np.where(moving, v, 0.0), np.where(moving, acc, 0.0), np.exp(-psi) - vp

    y, v, psi = np.zeros(n), np.zeros(n), p.copy()
    moving = np.zeros(n, dtype=bool)
    moving[epicenter] = True
    t, steps = 0.0, 0
    start = time.perf_counter()
    while moving.any() and steps < max_steps:
        k1 = rates(t, y, v, psi, moving)
        k2 = rates(t + dt / 2, y + dt / 2 * k1[0], v + dt / 2 * k1[1], psi + dt / 2 * k1[2], moving)
        k3 = rates(t + dt / 2, y + dt / 2 * k2[0], v + dt / 2 * k2[1], psi + dt / 2 * k2[2], moving)
        k4 = rates(t + dt, y + dt * k3[0], v + dt * k3[1], psi + dt * k3[2], moving)
        y = y + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        psi = psi + dt / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        t += dt
        steps += 1
        stuck = moving & (v <= 0)
        v[stuck] = 0.0
        moving &= ~stuck
        excess = f + nu * t - y + l2 * lap(y) - b * psi
        moving |= (~moving) & (excess > 0)
    return y, time.perf_counter() - start, steps * n


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800)
    p.add_argument("--b", type=float, default=20.0)
    p.add_argument("--transient", type=int, default=300)
    p.add_argument("--dts", type=float, nargs="+", default=[2e-3, 1e-3, 5e-4, 2.5e-4])
    p.add_argument("--numpy-dts", type=float, nargs="+", default=[1e-3, 5e-4])
    p.add_argument("--rtols", type=float, nargs="+", default=[1e-4, 1e-5, 1e-6, 1e-7, 1e-8])
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args()
    model = Model(N=args.N, b=args.b)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for label, (f, psi, epicenter, mu) in pre_event_states(model, args.transient).items():
        ref, _ = kernel_event(f, psi, epicenter, model, Integrator(dt=min(args.dts) / 4))

        def record(method, dt, profile, wall, work):
            slip_err = abs(profile.sum() - ref.slip) / ref.slip
            prof_err = np.linalg.norm(profile - ref.profile) / np.linalg.norm(ref.profile)
            rows.append({"event": label, "mu": mu, "method": method, "dt": dt, "slip_error": slip_err,
                         "profile_error": prof_err, "seconds": wall, "block_rhs": work})
            knob = "rtol" if method in STAGES else "dt"
            print(f"{label:5s} mu={mu:.2f} {method:9s} {knob}={dt:.0e}: slip error {slip_err:.1e}, "
                  f"profile error {prof_err:.1e}, {wall:.3f} s, {work:.3g} block RHS evaluations")

        for dt in args.dts:
            ev, wall = kernel_event(f, psi, epicenter, model, Integrator(dt=dt))
            record("rk4", dt, ev.profile, wall, 4 * ev.block_steps)
        for method, stages in STAGES.items():
            for rtol in args.rtols:
                ev, wall = kernel_event(f, psi, epicenter, model, Integrator(method=method, rtol=rtol))
                record(method, rtol, ev.profile, wall, stages * ev.block_steps)
        for dt in args.numpy_dts:
            y, wall, work = numpy_rk4_event(f, psi, epicenter, model, dt)
            record("numpy-rk4", dt, y, wall, 4 * work)
    (out / f"work_precision_N{args.N}_b{args.b:g}.json").write_text(json.dumps(rows, indent=1))
    plot(rows, out / f"work_precision_N{args.N}_b{args.b:g}.png", f"N = {args.N}, b = {args.b:g}")


def plot(rows, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, label in zip(axes, ("small", "large")):
        for k, method in enumerate(("rk4", "numpy-rk4", *STAGES)):
            sel = [r for r in rows if r["event"] == label and r["method"] == method]
            if sel:
                ax.loglog([r["seconds"] for r in sel], [max(r["slip_error"], 1e-17) for r in sel],
                          "o-", color=f"C{k}", label=method)
                for r in sel:
                    ax.annotate(f"{r['dt']:.0e}", (r["seconds"], max(r["slip_error"], 1e-17)), fontsize=6)
        mu = next((r["mu"] for r in rows if r["event"] == label), float("nan"))
        ax.set_title(f"{label} event (mu = {mu:.2f})", fontsize=9)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative slip error")
        ax.legend(fontsize=8)
    fig.suptitle(f"work-precision, single events, {title}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
