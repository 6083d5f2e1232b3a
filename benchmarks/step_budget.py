"""Where an event's time goes: block-steps per block that slid, and the cost of one block-step.

    python -m benchmarks.step_budget [--N 800] [--b 20] [--runs SETTING ...] [--transient 1000]
                                     [--min-seconds 0.1] [--out benchmarks/results]

From fixed pre-event states of a developed chain (the next small event, mu < 3, the next large
one, 4 <= mu < 5, and the next system-size one, mu >= 5), integrates each event with every setting
of `--runs` and reports, per event and setting: relative slip error against `--reference`, wall
time (fastest of repeats), steps tried, rejected steps, steps cut at a located stick or onset,
accepted block-steps (sum over steps of the sliding blocks), block-steps per block that slid, and
wall time per accepted block-step (rejections, located transitions and bookkeeping included).

Separately it times each method's step alone (a numba loop over one step of 4 sliding blocks in a
typical sliding state, y ~ 100, v ~ 300, psi ~ -5.5, with a step the error control accepts), the
floor of the cost of a block-step (every stage evaluated: exp4's reuse of its last evaluation as the
next step's first shows in the events, not here).

Every method's speed-up over the first setting (RK4) on an event factors exactly into
    (block-steps per slid block, RK4 / method) x (time per block-step, RK4 / method),
which the table prints side by side: how much the step control saves, and how much more each of
its steps costs. Writes step_budget_N{N}_b{b}.{json,txt}. Default run: about 2 min.
"""
import time

import numba as nb
import numpy as np

from ensemble.config import Model
from ensemble.events import check, run_event
from ensemble.integrators import kernel_params
from ensemble.model.methods import take_step
from ensemble.model.steppers import FIRST_NEW
from ensemble.model.workspace import F0, NCOLS, P, P0, V, V0, Y, Y0, YS

from .common import parse_setting, single_event_parser, write_outputs
from .work_precision import kernel_event, pre_event_states

RUNS = ["rk4:dt=1e-3", "ark4:rtol=1e-4", "ark4:rtol=3e-5", "ark4:rtol=1e-5", "ark4:rtol=3e-6", "ark5:rtol=3e-5",
        "ark5:rtol=1e-5", "exp4:rtol=1e-4", "exp4:rtol=1e-3"]
SIZES = ["small:-inf:3", "large:4:5", "system-size:5:inf"]
SLIDING = 4     # blocks sliding in the step-alone timing


@nb.njit(cache=True)
def _repeat_step(W, act, na, h, p, reps):
    total = 0.0
    for _ in range(reps):
        total += take_step(W, act, na, W.shape[0], 0.0, h, p, 0.0, FIRST_NEW, (0.0, 0.0))[2]
    return total


def step_alone_ns(setting, model, reps=200_000):
    """Nanoseconds per block-step of one step of `setting`'s method, 4 blocks sliding (best of 3)."""
    integ = setting.integrator()
    p = kernel_params(model, integ)
    n = 16
    W = np.zeros((n, NCOLS))
    act = np.arange(6, 6 + SLIDING).astype(np.int64)
    for k, i in enumerate(act):
        W[i, Y0] = W[i, Y] = W[i, YS] = 100.0 + 10.0 * k
        W[i, V0] = W[i, V] = 300.0 - 50.0 * k
        W[i, P0] = W[i, P] = -5.5 - 0.1 * k
        W[i, F0] = model.b * 26.0
    h = p.dt
    if integ.method != "rk4":     # a step the error control would accept
        h = 0.01
        while _repeat_step(W.copy(), act, SLIDING, h, p, 1) > 1.0:
            h /= 2
    _repeat_step(W.copy(), act, SLIDING, h, p, 10)
    best = np.inf
    for _ in range(3):
        work = W.copy()
        start = time.perf_counter()
        _repeat_step(work, act, SLIDING, h, p, reps)
        best = min(best, time.perf_counter() - start)
    return best / (reps * SLIDING) * 1e9


def parse_sizes(texts):
    """['label:low:high', ...] -> {label: (low, high)}."""
    sizes = {}
    for text in texts:
        label, *bounds = text.split(":")
        try:
            low, high = map(float, bounds)
        except ValueError:
            raise SystemExit(f"--sizes {text!r}: expected LABEL:LOW:HIGH with numbers LOW < HIGH") from None
        if not low < high:
            raise SystemExit(f"--sizes {text!r}: expected LOW < HIGH")
        sizes[label] = (low, high)
    return sizes


def measure(model, states, settings, reference, min_seconds=0.1):
    rows = []
    for label, (f, p, epicenter, mu) in states.items():
        ref = check(run_event(f, p, epicenter, model, reference.integrator()))
        n_slid = int(np.sum(ref.profile > 0))
        for s in settings:
            ev, wall = kernel_event(f, p, epicenter, model, s.integrator(), min_seconds)
            rows.append({"event": label, "mu": mu, "n_slid": n_slid, "setting": s.label,
                         "slip_error": abs(ev.slip - ref.slip) / ref.slip, "seconds": wall,
                         "steps": ev.steps, "rejected": ev.rejected, "cuts": ev.cuts,
                         "block_steps": ev.block_steps, "block_steps_per_slid": ev.block_steps / n_slid,
                         "ns_per_block_step": wall / ev.block_steps * 1e9})
            r = rows[-1]
            print(f"{label} mu={mu:.2f} {s.label}: slip error {r['slip_error']:.1e}, {wall * 1e3:.2f} ms, "
                  f"{r['block_steps_per_slid']:.0f} block-steps per slid block", flush=True)
    return rows


def table(rows, alone, title):
    base = rows[0]["setting"]
    lines = [f"step budget, single events, {title}",
             f"speed-up over {base} = (block-steps per slid block, {base} / method) x "
             f"(ns per block-step, {base} / method)",
             f"{'event':11s} {'mu':>5s} {'slid':>5s} {'setting':16s} {'slip err':>8s} {'ms':>8s} {'steps':>7s} "
             f"{'rejected':>8s} {'cuts':>5s} {'bs/slid':>7s} {'ns/bs':>6s} {'speed-up':>8s} {'= steps':>7s} "
             f"{'x cost':>6s}"]
    for event in dict.fromkeys(r["event"] for r in rows):
        here = [r for r in rows if r["event"] == event]
        b0 = next(r for r in here if r["setting"] == base)
        for r in here:
            fewer = b0["block_steps_per_slid"] / r["block_steps_per_slid"]
            cheaper = b0["ns_per_block_step"] / r["ns_per_block_step"]
            lines.append(f"{event:11s} {r['mu']:5.2f} {r['n_slid']:5d} {r['setting']:16s} "
                         f"{r['slip_error']:8.1e} {r['seconds'] * 1e3:8.2f} {r['steps']:7d} "
                         f"{r['rejected']:8d} {r['cuts']:5d} {r['block_steps_per_slid']:7.0f} "
                         f"{r['ns_per_block_step']:6.0f} {fewer * cheaper:8.2f} {fewer:7.2f} {cheaper:6.2f}")
    lines.append(f"\none step alone, {SLIDING} sliding blocks: ns per block-step")
    for label, ns in alone.items():
        lines.append(f"  {label:16s} {ns:6.0f}")
    return lines


def parse_args(argv=None):
    p = single_event_parser(__doc__, RUNS, SIZES, "kernel settings (see benchmarks/common.py); the first is "
                                                  "the baseline of the ratios")
    p.add_argument("--reference", default="rk4:dt=1.25e-4", help="kernel setting for the reference slip")
    p.add_argument("--min-seconds", type=float, default=0.1,
                   help="repeat each event for at least this long (the fastest repeat counts; more on a busy machine)")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    settings = [parse_setting(text) for text in args.runs]
    reference = parse_setting(args.reference)
    model = Model(N=args.N, b=args.b)
    states = pre_event_states(model, args.transient, args.seed, parse_sizes(args.sizes))
    rows = measure(model, states, settings, reference, args.min_seconds)
    alone = {s.label: step_alone_ns(s, model) for s in settings}
    title = f"N = {args.N}, b = {args.b:g}, reference {reference.label}"
    data = {"config": {**vars(args), "reference": reference.label}, "rows": rows, "step_alone_ns": alone}
    write_outputs(args.out, f"step_budget_N{args.N}_b{args.b:g}", data, table(rows, alone, title))
    return data


if __name__ == "__main__":
    main()
