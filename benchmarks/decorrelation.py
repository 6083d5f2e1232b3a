"""How fast two branches of one spun-up chain decorrelate: what sets the decorrelation stretch.

    python -m benchmarks.decorrelation [--N 800] [--b 20 50] [--spinup 8000] [--branches 4]
                                       [--repeats 1] [--events 3000] [--perturbation 1e-9 1e-6 1e-3]
                                       [--setting ark4] [--window 10] [--out benchmarks/results]

Per point (N, b; every pair of --N x --b): task 0 of the point is spun up for --spinup events
(the branch point); from that state start an unperturbed continuation (the reference) and, per
perturbation size, --branches branches, each with its forces lowered as a branched run lowers them
(ensemble.run.tasks.perturb with branch_rng of its own task). Branch j of a repeat uses the same
generator at every perturbation size, so that only the size differs. With --repeats R > 1 the
reference's state after --events events is the next branch point (R branch points per point).
Independent pairs: task 1 of the point, spun up alike, against the reference and every branch.
All trajectories run event by event, and the measures are functions of k, the reference's events
since the branch point:

- stress: the force profiles of a pair at one time, midway between the end of the reference's
  event k and the onset of its event k + 1 (each trajectory's state brought to that time from
  before its first event with a later onset: time-aligned, so a delayed onset is not a stress
  difference, and equal times are what "the same state" means; the lazily stored forces of a
  checkpoint hold at each block's own time and would differ by nu dt). The measure is the
  normalized RMS difference of the profiles, mean removed,
      D = sqrt(var(F_a - F_b) / (var F_a + var F_b)),
  0 for equal profiles and about 1 for uncorrelated ones. An independent pair is compared at the
  same time since its own branch point (the independent trajectory's last event end before it).
- event sequences: the first event (1-based, at equal index) whose epicenter or number of slipped
  blocks differs from the reference's; and the agreement over windows of --window reference
  events: the fraction of them that the other trajectory matches (same epicenter and n_slipped,
  onset within --tolerance mean inter-event times, times since the branch point). Time-aligned,
  because one extra small event shifts every later index while the rest stays alike.

The rule: both measures are averaged over windows of --window reference events (k = 1..W, W+1..2W,
...; the first window mean of D is over the states after events 1..W). Measured as a distance from
identity (D itself; 1 - agreement, the fraction of unmatched events), a branch has decorrelated
after the end of the first window from which its window means stay at least half the smallest window
mean of any independent pair of the point (all pairs, windows and branch points), to the end of
the run: D >= min_indep(D) / 2, agreement <= (1 + max_indep(agreement)) / 2. A branch still
closer to identity in the last window has not decorrelated within the run (reported as "> events").
Why half the extreme and not the extreme or a quantile: the branches are as many samples of the
decorrelated state as the independent pairs, so a decorrelated branch falls below the independent
minimum by chance about half the time, and below a 1% quantile at some point of hundreds of
windows almost surely; a branch approaches from identity through orders of magnitude of D, so the
factor 2 costs a few events at most. Whether anything is left of the shared origin after that is
the column "late D": the median of the branches' D over the second half of each branch point's
run against the independent pairs' (1: nothing is left; meaningful when the run is at least twice
the decorrelation length).
Writes decorrelation.{txt,json,png} (figure: the measures against k, the independent band shaded).
"""
import argparse
import itertools

import numpy as np

from ensemble.config import Config, Model, Run
from ensemble.store.checkpoint import Checkpoint
from ensemble.model.workspace import D_NSLIP
from ensemble.run.trajectory import Trajectory
from ensemble.run.tasks import branch_rng, perturb
from ensemble.sweep import task_list

from .common import Clock, minutes, parse_setting, pyplot, save_figure, write_outputs

PERTURBATIONS = [1e-9, 1e-6, 1e-3]


class Follower:
    """A trajectory run one event at a time whose forces can be read at any time up to its next onset.

    Per event integrated so far (the last one pending: integrated, its onset after every time
    asked for yet): `onsets`, `epicenters`, `slipped`, and `rest`, the time of the state before it
    (the end of the event before, or the start).
    """

    def __init__(self, traj):
        self.traj = traj
        self.onsets, self.epicenters, self.slipped, self.rest = [], [], [], []
        self.step()

    def step(self):
        self.before = self.traj.checkpoint()      # the state before the pending event
        self.rest.append(float(self.before.clock[0] + self.before.clock[1]))
        t, epicenter, diag = self.traj.advance(1)
        self.onsets.append(float(t[0]))
        self.epicenters.append(int(epicenter[0]))
        self.slipped.append(int(diag[0, D_NSLIP]))

    def force_at(self, t):
        """Forces of every block at time t (not before the end of the last event it has passed), c-free frame."""
        while self.onsets[-1] <= t:
            self.step()
        since = self.before.since
        wait = np.maximum((t - since[:, 0]) - since[:, 1], 0.0)
        return self.before.force + self.traj.task.model.nu * wait

    def sequence(self, start, t0):
        """(onsets - t0, epicenters, n_slipped) of the events from index `start` on."""
        return (np.array(self.onsets[start:]) - t0, np.array(self.epicenters[start:]),
                np.array(self.slipped[start:]))


def profile_distance(fa, fb):
    """Normalized RMS difference of two force profiles, mean removed: 0 equal, ~1 uncorrelated."""
    a, b = fa - fa.mean(), fb - fb.mean()
    scale = np.mean(a * a) + np.mean(b * b)
    return float(np.sqrt(np.mean((a - b) ** 2) / scale)) if scale > 0 else 0.0


def first_difference(ref, other):
    """1-based number of the first event whose (epicenter, n_slipped) differ at equal index, or None."""
    n = min(len(ref[1]), len(other[1]))
    differ = (ref[1][:n] != other[1][:n]) | (ref[2][:n] != other[2][:n])
    return int(np.argmax(differ)) + 1 if differ.any() else None


def matched(ref, other, tol):
    """Per reference event: has `other` an event of its epicenter and n_slipped with an onset (time
    since its own branch point) within tol of the reference's?"""
    t, epicenter, slipped = other
    lo = np.searchsorted(t, ref[0] - tol, side="left")      # onsets increase
    hi = np.searchsorted(t, ref[0] + tol, side="right")
    return np.array([bool(np.any((epicenter[a:b] == e) & (slipped[a:b] == s)))
                     for a, b, e, s in zip(lo, hi, ref[1], ref[2])])


def window_means(x, window):
    """Means over consecutive windows of `window` values (a last partial window is dropped)."""
    n = len(x) // window
    return np.asarray(x[:n * window], dtype=float).reshape(n, window).mean(axis=1)


def settled(values, edge, rising=True):
    """The first index from which every value is >= edge (rising; else <= edge), None if the last is not."""
    values = np.asarray(values)
    good = values >= edge if rising else values <= edge
    if not len(good) or not good[-1]:
        return None
    bad = np.flatnonzero(~good)
    return int(bad[-1]) + 1 if len(bad) else 0


def decorrelation_length(values, edge, window, rising=True):
    """Events until the end of the first window from which the window means of `values` (one per
    event k = 1, 2, ...) stay beyond `edge` (module docstring), None if the last window is not."""
    w = settled(window_means(values, window), edge, rising)
    return None if w is None else (w + 1) * window


def edges(noise_windows, noise_agree_windows):
    """The rule's edges (module docstring) from the window means of the independent pairs."""
    return {"distance": 0.5 * float(np.min(noise_windows)),
            "agree": 0.5 * (1.0 + float(np.max(noise_agree_windows)))}


def branched(cfg, task, start, perturbation, rng):
    """A trajectory from the checkpoint `start` (copied), forces lowered by U[0, perturbation)."""
    force = perturb(start.force, perturbation, rng) if perturbation else start.force.copy()
    return Trajectory(cfg, task, checkpoint=Checkpoint(force, start.psi.copy(), start.since.copy(),
                                                       start.clock.copy(), 0))


def run_repeat(cfg, tasks, start, independent, args, repeat):
    """One branch point: every branch against the reference, and the independent pairs.

    Returns the stress measure D per branch and k (0..events), the same of the independent pairs
    (the independent trajectory against the reference and each branch), the sequence agreement per
    reference event (matched or not) of each branch and of the independent trajectory (with the
    reference only: a branch may hold fewer events than the reference by the end), the first
    differing events, and the reference's state after `events` events.
    """
    reference = Follower(branched(cfg, tasks[0], start, 0.0, None))
    t0 = reference.rest[0]
    branches = [Follower(branched(cfg, tasks[0], start, p, branch_rng(cfg, tasks[repeat * args.branches + j])))
                for p in args.perturbation for j in range(args.branches)]
    mark = len(independent.onsets) - 1           # its pending event: the first since its branch point
    t0_independent = independent.rest[mark]
    distance = np.empty((len(branches), args.events + 1))
    noise = np.empty((len(branches) + 1, args.events + 1))
    for k in range(args.events + 1):
        while len(reference.onsets) <= k:
            reference.step()
        t = 0.5 * (reference.rest[k] + reference.onsets[k])    # between the reference's events k and k + 1
        f_ref = reference.force_at(t)
        f_ind = independent.force_at(t - t0 + t0_independent)
        noise[-1, k] = profile_distance(f_ind, f_ref)
        for i, branch in enumerate(branches):
            f = branch.force_at(t)
            distance[i, k] = profile_distance(f, f_ref)
            noise[i, k] = profile_distance(f_ind, f)
    ref_seq = tuple(x[:args.events] for x in reference.sequence(0, t0))
    tol = args.tolerance * (reference.rest[args.events] - t0) / args.events
    ind_seq = independent.sequence(mark, t0_independent)
    seqs = [branch.sequence(0, t0) for branch in branches]
    return {"distance": distance, "noise": noise,
            "agree": np.array([matched(ref_seq, s, tol) for s in seqs]),
            "noise_agree": matched(ref_seq, ind_seq, tol)[None, :],
            "first": [first_difference(ref_seq, s) for s in seqs],
            "next_start": reference.before, "events": len(reference.onsets) + sum(len(b.onsets) for b in branches)}


def measure_point(N, b, setting, args, clock):
    """Spin up, branch --repeats times, and reduce: curves, bands and decorrelation lengths per perturbation."""
    cfg = Config(model=Model(N=N, b=b), run=Run(seeds=max(2, args.repeats * args.branches), seed=args.seed),
                 integrator=setting.integrator())
    tasks = task_list(cfg)
    spun = Trajectory(cfg, tasks[0])
    spun.advance(args.spinup)
    other = Trajectory(cfg, tasks[1])
    other.advance(args.spinup)
    independent = Follower(other)
    start = spun.checkpoint()
    spin_seconds = clock.elapsed
    runs = []
    for r in range(args.repeats):
        runs.append(run_repeat(cfg, tasks, start, independent, args, r))
        start = runs[-1].pop("next_start")
        print(f"  N = {N}, b = {b:g}: branch point {r + 1}/{args.repeats} done ({minutes(clock.elapsed)})", flush=True)
    return reduce(runs, args, N, b) | {
        "spinup_seconds": spin_seconds, "seconds": clock.elapsed - spin_seconds,
        "events_per_second": sum(run["events"] for run in runs) / max(clock.elapsed - spin_seconds, 1e-9)}


def reduce(runs, args, N, b):
    """Bands, edges, curves and decorrelation lengths per perturbation from the branch points' runs."""
    w = args.window
    noise = np.concatenate([run["noise"] for run in runs])
    noise_agree = np.concatenate([run["noise_agree"] for run in runs])
    noise_w = np.array([window_means(x[1:], w) for x in noise])
    noise_agree_w = np.array([window_means(x, w) for x in noise_agree])
    edge = edges(noise_w, noise_agree_w)
    half = args.events // 2
    late_noise = float(np.median(noise[:, half:]))
    per = []
    for i, p in enumerate(args.perturbation):
        rows = slice(i * args.branches, (i + 1) * args.branches)
        distance = np.concatenate([run["distance"][rows] for run in runs])
        agree = np.concatenate([run["agree"][rows] for run in runs])
        per.append({"perturbation": p,
                    "first_difference": [f for run in runs for f in run["first"][rows]],
                    "stress_events": [decorrelation_length(d[1:], edge["distance"], w) for d in distance],
                    "sequence_events": [decorrelation_length(a, edge["agree"], w, rising=False) for a in agree],
                    "late_distance_ratio": float(np.median(distance[:, half:])) / late_noise,
                    "distance": _spread(distance),
                    "agree": _spread(np.array([window_means(a, w) for a in agree]))})
    return {"N": N, "b": b, "edges": edge, "perturbations": per,
            "band": {"distance": [float(noise_w.min()), float(np.median(noise_w)), float(noise_w.max())],
                     "agree": [float(noise_agree_w.min()), float(noise_agree_w.mean()), float(noise_agree_w.max())]},
            "noise_distance_median": _digits(np.median(noise, axis=0)),
            "noise_agree_mean": _digits(noise_agree_w.mean(axis=0))}


def _spread(curves):
    """Median and range over branches of curves (branch x k), to 3 digits (the JSON's size)."""
    return {"median": _digits(np.median(curves, axis=0)), "min": _digits(curves.min(axis=0)),
            "max": _digits(curves.max(axis=0))}


def _digits(x, n=3):
    return np.array([float(f"{v:.{n}g}") for v in x])


def longest(p):
    """The largest of a perturbation's decorrelation lengths (both measures), None if one never settled."""
    lengths = p["stress_events"] + p["sequence_events"]
    return None if None in lengths else max(lengths)


def _summary(values, events):
    """'median [min, max]' of event counts; None (never) counts as above the run's length."""
    if not values:
        return "-"
    known = sorted(v for v in values if v is not None)
    never = len(values) - len(known)
    if not known:
        return f"> {events} (all {never})"
    text = f"{int(np.median(known))} [{known[0]}, {known[-1]}]"
    return text + (f", {never} > {events}" if never else "")


def suggestion(points, safety):
    """(events, per block) of the suggested decorrelation stretch: `safety` x the longest measured
    length, the largest over the points (per block: of length / N); None if a branch never settled."""
    found = [(longest(p), pt["N"]) for pt in points for p in pt["perturbations"]]
    if any(k is None for k, _ in found):
        return None
    return safety * max(k for k, _ in found), safety * max(k / n for k, n in found)


def table(points, args, command):
    lines = [f"# {command}",
             f"decorrelation of branches: {args.branches} branches x {args.repeats} branch point(s) per "
             f"perturbation, {args.events} events after a spin-up of {args.spinup}, {args.setting}; "
             f"k = reference events since the branch point",
             "| N | b | perturbation | first differing event | sequences decorrelated after | "
             "stress decorrelated after | longest / N | late D / independent | D edge (independent range) | "
             "agreement edge (independent range) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for pt in points:
        d, a, e = pt["band"]["distance"], pt["band"]["agree"], pt["edges"]
        for p in pt["perturbations"]:
            k = longest(p)
            lines.append(f"| {pt['N']} | {pt['b']:g} | {p['perturbation']:g} | "
                         f"{_summary(p['first_difference'], args.events)} | "
                         f"{_summary(p['sequence_events'], args.events)} | "
                         f"{_summary(p['stress_events'], args.events)} | "
                         f"{'-' if k is None else format(k / pt['N'], '.3f')} | {p['late_distance_ratio']:.2f} | "
                         f"{e['distance']:.3f} ({d[0]:.3f} .. {d[2]:.3f}) | "
                         f"{e['agree']:.2f} ({a[0]:.2f} .. {a[2]:.2f}) |")
    lines.append(f"cells: median [min, max] over branches of events k; D = normalized RMS difference of the force "
                 f"profiles (0 equal, ~1 uncorrelated), time-aligned; agreement: fraction of the reference's events "
                 f"matched (epicenter, n_slipped, onset within {args.tolerance:g} mean inter-event times); both "
                 f"averaged over windows of {args.window} events; decorrelated from the first window after which every "
                 f"window is beyond the edge (half the independent pairs' extreme distance from identity); late D / "
                 f"independent: medians over the second half of the run")
    lines.append("events/s (reference and branches, all trajectories of a point): "
                 + ", ".join(f"N = {pt['N']}, b = {pt['b']:g}: {pt['events_per_second']:.0f}" for pt in points))
    s = suggestion(points, args.safety)
    lines.append("suggested decorrelation stretch: " + (
        "- (some branch did not decorrelate within the run)" if s is None else
        f"{args.safety:g} x the longest = {int(np.ceil(s[0]))} events, or {s[1]:.2f} events per block"))
    return lines


def plot(points, args, path):
    plt = pyplot()
    fig, axes = plt.subplots(2, len(points), figsize=(4.2 * len(points), 6.8), squeeze=False)
    k = np.arange(args.events + 1)
    centres = (np.arange(args.events // args.window) + 0.5) * args.window
    for col, pt in enumerate(points):
        top, bottom = axes[0, col], axes[1, col]
        a, d, e = pt["band"]["agree"], pt["band"]["distance"], pt["edges"]
        top.axhspan(a[0], max(a[2], 1e-3), color="0.85", label="independent pairs (range)")
        top.axhline(e["agree"], color="0.4", ls=":", lw=0.8, label="edge of the rule")
        bottom.axhspan(d[0], d[2], color="0.85")
        bottom.axhline(e["distance"], color="0.4", ls=":", lw=0.8)
        bottom.plot(k[1:], pt["noise_distance_median"][1:], color="0.5", lw=0.8)
        for i, p in enumerate(pt["perturbations"]):
            color = f"C{i}"
            top.plot(centres, p["agree"]["median"], color=color, lw=1.2, label=f"perturbation {p['perturbation']:g}")
            bottom.plot(k[1:], p["distance"]["median"][1:], color=color, lw=1.2)
            bottom.fill_between(k[1:], p["distance"]["min"][1:], p["distance"]["max"][1:], color=color, alpha=0.15)
            if longest(p) is not None:
                for ax in (top, bottom):
                    ax.axvline(max(longest(p), 1), color=color, ls="--", lw=0.8)
        top.set(xscale="log", ylim=(-0.02, 1.02), title=f"N = {pt['N']}, b = {pt['b']:g}",
                ylabel=f"events matched (windows of {args.window})")
        bottom.set(xscale="log", yscale="log", xlabel="events since the branch point (reference)",
                   ylabel="normalized RMS difference of forces D")
        for ax in (top, bottom):
            ax.tick_params(labelsize=7)
    save_figure(fig, axes, "branches against their unperturbed continuation\n(median, shaded: range; grey: "
                "independent pairs; dashed: longest)", path)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, nargs="+", default=[800], help="blocks (every N with every b)")
    p.add_argument("--b", type=float, nargs="+", default=[20.0, 50.0])
    p.add_argument("--spinup", type=int, default=8000, help="events before the first branch point")
    p.add_argument("--branches", type=int, default=4, help="branches per perturbation and branch point")
    p.add_argument("--repeats", type=int, default=1, help="branch points, --events apart on the reference")
    p.add_argument("--events", type=int, default=3000, help="events after each branch point (of the reference)")
    p.add_argument("--perturbation", type=float, nargs="+", default=PERTURBATIONS,
                   help="largest force decrement of a block (model force units); 0: a branch equal to the reference")
    p.add_argument("--setting", default="ark4", help="kernel integrator setting, e.g. ark4:rtol=1e-5")
    p.add_argument("--window", type=int, default=10, help="reference events per window of both measures (the rule)")
    p.add_argument("--tolerance", type=float, default=0.5, help="onsets match within this many mean inter-event times")
    p.add_argument("--safety", type=float, default=3.0, help="suggested stretch = safety x the longest length")
    p.add_argument("--seed", type=int, default=0, help="root seed")
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    if args.events < args.window:
        p.error("--events must be at least --window")
    if min(args.perturbation) < 0:
        p.error("--perturbation must be >= 0")
    return args


def main(argv=None):
    args = parse_args(argv)
    setting = parse_setting(args.setting)
    command = "python -m benchmarks.decorrelation " + " ".join(
        f"--{k} {' '.join(map(str, v)) if isinstance(v, list) else v}" for k, v in vars(args).items() if k != "out")
    print(f"{len(args.N) * len(args.b)} point(s): 2 x {args.spinup} spin-up events, then {args.repeats} x "
          f"{len(args.perturbation) * args.branches + 2} trajectories x {args.events} events", flush=True)
    points = []
    for N, b in itertools.product(args.N, args.b):
        points.append(measure_point(N, b, setting, args, Clock()))
    data = {"config": vars(args), "points": points}
    write_outputs(args.out, "decorrelation", data, table(points, args, command))
    plot(points, args, f"{args.out}/decorrelation.png")
    return data


if __name__ == "__main__":
    main()
