"""What sets the adaptive step: the block and the part of its state whose error limits each step.

    python -m benchmarks.step_trace [--N 800] [--b 20] [--runs SETTING ...] [--transient 1000]
                                    [--out benchmarks/results]

From the same fixed pre-event states as the step budget (the next large event, 4 <= mu < 5, and
the next system-size one, mu >= 5, of a developed chain), integrates each event with every adaptive
setting of `--runs` and records every step tried (ensemble.model.workspace.TRACE_COLUMNS). For the
accepted steps it reports, weighted by block-steps (the work):

- which part of the limiting block's error set the step: slip, velocity or the state psi;
- where that block was in its slide, by ln(theta v) = psi + ln v, which steady sliding holds at 0:
  "onset/knee" (> 0.1: it started recently and its state has not yet relaxed onto steady sliding,
  the knee where psi turns from falling with the slip to following -ln v), "steady" (|.| <= 0.1),
  "stopping" (< -0.1 or v <= 0: v falls faster than the state can follow);
- the same for the rejected steps (share of steps tried);
- the mean number of sliding blocks per step, and the bound on the gain of per-block steps
  (multirate): the block-steps had every block taken the step its own error allows (at most 10x
  the common one), an optimistic bound that ignores the cost of coupling blocks with different steps.

Writes step_trace_N{N}_b{b}.{json,txt}. Default run: about 1 min.
"""
import numpy as np

from ensemble.config import Model
from ensemble.events import check, run_event
from ensemble.model.workspace import NTRACE, T_ERROR, T_OWN, T_PART, T_PSI, T_SLIDING, T_V

from .common import parse_setting, single_event_parser, write_outputs
from .step_budget import parse_sizes
from .work_precision import pre_event_states

RUNS = ["ark4:rtol=1e-5", "ark4:rtol=3e-6", "ark5:rtol=3e-5", "ark4:rtol=1e-4", "exp4:rtol=1e-4"]
SIZES = ["large:4:5", "system-size:5:inf"]
PARTS = ("slip", "velocity", "psi")
PHASES = ("onset/knee", "steady", "stopping")
STEADY = 0.1    # |ln(theta v)| below this: steady sliding


def phase(v, psi):
    """Phase index (PHASES) of blocks with velocity v and state psi (arrays)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.where(v > 0, psi + np.log(np.where(v > 0, v, 1.0)), -np.inf)
    return np.where(x > STEADY, 0, np.where(x >= -STEADY, 1, 2))


def trace_event(f, p, epicenter, model, integrator, rows=1_000_000):
    """(EventResult, trace rows of the steps tried) of one event."""
    trace = np.zeros((rows, NTRACE))
    ev = check(run_event(f, p, epicenter, model, integrator, trace=trace))
    if ev.steps > rows:
        raise RuntimeError(f"step trace: {ev.steps} steps, more than {rows} rows")
    return ev, trace[:ev.steps]


def summarize(trace):
    """Shares of the work by limiting part and phase, rejections, sliding blocks, multirate bound."""
    accepted = trace[:, T_ERROR] <= 1.0
    acc = trace[accepted]
    work = acc[:, T_SLIDING]
    where = phase(acc[:, T_V], acc[:, T_PSI])
    rejected = trace[~accepted]
    where_rej = phase(rejected[:, T_V], rejected[:, T_PSI])
    return {
        "steps": len(trace), "rejected": len(rejected), "block_steps": float(work.sum()),
        "part_share": {name: float(work[acc[:, T_PART] == k].sum() / work.sum()) for k, name in enumerate(PARTS)},
        "phase_share": {name: float(work[where == k].sum() / work.sum()) for k, name in enumerate(PHASES)},
        "rejected_share": {name: float(np.sum(where_rej == k) / len(trace)) for k, name in enumerate(PHASES)},
        "sliding_per_step": float(work.mean()),
        "multirate_bound": float(work.sum() / acc[:, T_OWN].sum()),
    }


def measure(model, states, settings):
    rows = []
    for label, (f, p, epicenter, mu) in states.items():
        for s in settings:
            _, trace = trace_event(f, p, epicenter, model, s.integrator())
            rows.append({"event": label, "mu": mu, "setting": s.label, **summarize(trace)})
            print(f"{label} mu={mu:.2f} {s.label}: {len(trace)} steps traced", flush=True)
    return rows


def table(rows, title):
    lines = [f"step trace, single events, {title}",
             "shares of the accepted block-steps by what limited the step: the part of the limiting block's",
             "error, and that block's phase by ln(theta v) (onset/knee > 0.1 >= steady >= -0.1 > stopping);",
             "rejected: steps rejected in each phase / steps tried; multirate bound: block-steps / block-steps",
             "had every block taken its own step",
             f"{'event':11s} {'setting':15s} {'slip':>5s} {'vel':>5s} {'psi':>5s} | {'knee':>5s} {'steady':>6s} "
             f"{'stop':>5s} | {'rej knee':>8s} {'steady':>6s} {'stop':>5s} | {'sliding':>7s} {'multirate':>9s}"]
    for r in rows:
        part, ph, rej = r["part_share"], r["phase_share"], r["rejected_share"]
        lines.append(f"{r['event']:11s} {r['setting']:15s} {part['slip']:5.2f} {part['velocity']:5.2f} "
                     f"{part['psi']:5.2f} | {ph['onset/knee']:5.2f} {ph['steady']:6.2f} {ph['stopping']:5.2f} | "
                     f"{rej['onset/knee']:8.2f} {rej['steady']:6.2f} {rej['stopping']:5.2f} | "
                     f"{r['sliding_per_step']:7.1f} {r['multirate_bound']:8.2f}x")
    return lines


def parse_args(argv=None):
    return single_event_parser(__doc__, RUNS, SIZES, "adaptive kernel settings (see benchmarks/common.py)"
                               ).parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    settings = [parse_setting(text) for text in args.runs]
    fixed = [s.label for s in settings if s.name == "rk4"]
    if fixed:
        raise SystemExit(f"--runs: {', '.join(fixed)} has no error control to trace (adaptive methods only)")
    model = Model(N=args.N, b=args.b)
    states = pre_event_states(model, args.transient, args.seed, parse_sizes(args.sizes))
    rows = measure(model, states, settings)
    data = {"config": vars(args), "rows": rows}
    write_outputs(args.out, f"step_trace_N{args.N}_b{args.b:g}", data,
                  table(rows, f"N = {args.N}, b = {args.b:g}"))
    return data


if __name__ == "__main__":
    main()
