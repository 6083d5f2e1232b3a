"""Every number `python -m analysis reduce` writes, against a plain brute-force recomputation.

Synthetic catalogs are written with the project's own writer (ensemble/store/writers.py's Rank0Writer on one
process), so they are real, verified catalogs; their events are drawn to sit on the edges the
reduction must get right: magnitudes exactly at mu_c, at the b-value cut, on bin edges and on
the top edge, recurrence times on T nu bin edges, successive large events exactly `window` and
`window + 1` blocks apart, recurrences that straddle chunks and stretches, interior and
boundary ruptures, empty and partly written tasks. The reference (tests/reduction_reference.py)
shares no code with analysis/. Intervals: the summary's equal the documented percentiles of
the same bootstrap resamples, and the percentile interval has its nominal coverage, tightly
enough to tell 95% from 97.5%.

The reductions run in this process (analysis.cli.main, as `python -m analysis reduce` calls it), but
those under `mpiexec -n 2`: a process of its own costs about 2.5 s of imports, more than the
reduction of these catalogs. The plain reference costs most of this file's time (it grows with the
square of a task's events): the catalogs hold 400 events a task where their edges need them, fewer
where only their count of seeds or tasks matters.
"""
import contextlib
import io
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from analysis import cli, stats
from analysis import options as reduce_options
from ensemble.store import reader, schema
from ensemble.config import loads
from ensemble.sweep import task_list

from . import reduction_reference as ref
from .catalog_writer import write_events
from .processes import run_bounded

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 300   # seconds for one reduction under mpiexec (they take a few)
LOG10_E = math.log10(math.e)

N_CHAIN = 40
OPT = {"mu_bins": (-1.0, 7.0, 32),     # width 0.25: magnitudes on the 0.25 grid sit on edges
       "tnu_bins": (0.0, 40.0, 40),    # width 1: grid times give T nu on the edges
       "mu_c": 4.0, "window": 3, "b_cut": 3.0, "bootstrap": 100, "seed": 11,
       # the rupture statistics on the synthetic chain of N_CHAIN blocks
       "lr_bins": (0.5, 40.5, 8), "lr_min": 2, "lr_max": 30, "class_min": 3, "uni_edge": 0.2}

# `python -m analysis reduce` with the rows streamed in chunks of argv[1] events (options.CHUNK has no
# command-line option): small chunks make recurrences straddle them (reduce_here: the same in this process)
REDUCE = ("import sys; from analysis import cli, options; "
          "options.CHUNK = int(sys.argv[1]); sys.exit(cli.main(sys.argv[2:]))")


def reduce_command(chunk, paths, out, level, blocks):
    """The reduction of one catalog (a path) or several (a list), with --partial: the synthetic
    catalogs hold unfinished tasks."""
    o = OPT
    paths = [str(p) for p in paths] if isinstance(paths, (list, tuple)) else [str(paths)]
    return [sys.executable, "-c", REDUCE, str(chunk), "reduce", *paths, "-o", str(out), "--partial",
            "--mu-bins={}:{}:{}".format(*o["mu_bins"]), "--tnu-bins={}:{}:{}".format(*o["tnu_bins"]),
            "--mu-c", str(o["mu_c"]), "--window", str(o["window"]), "--b-cut", str(o["b_cut"]),
            "--bootstrap", str(o["bootstrap"]), "--seed", str(o["seed"]), "--level", str(level),
            "--blocks", str(blocks), "--lr-bins={}:{}:{}".format(*o["lr_bins"]), "--lr-min", str(o["lr_min"]),
            "--lr-max", str(o["lr_max"]), "--class-min", str(o["class_min"]), "--uni-edge", str(o["uni_edge"])]


def run(cmd):
    env = dict(os.environ, PYTHONPATH=str(ROOT),
               NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))
    res = run_bounded(cmd, TIMEOUT, cwd=ROOT, env=env)
    assert res.returncode == 0, res.stderr
    return res


def reduce_here(chunk, paths, out, level, blocks, partial=True, check=True):
    """reduce_command's reduction run by analysis.cli.main in this process, as REDUCE runs it (the
    rows streamed in chunks of `chunk`); without --partial if not `partial`. A CompletedProcess with its
    exit code (which must be 0 if `check`) and what it printed."""
    args = reduce_command(chunk, paths, out, level, blocks)[4:]       # past python -c REDUCE chunk
    if not partial:
        args.remove("--partial")
    stdout, stderr = io.StringIO(), io.StringIO()
    default = reduce_options.CHUNK
    reduce_options.CHUNK = chunk
    try:
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            code = cli.main(args)
    finally:
        reduce_options.CHUNK = default
    res = subprocess.CompletedProcess(args, code, stdout.getvalue(), stderr.getvalue())
    assert not check or code == 0, res.stderr
    return res


def options(level, blocks):
    """The reference's options (bins as `parse_bins` documents them: n + 1 equal edges)."""
    return {"mu_edges": np.linspace(*OPT["mu_bins"][:2], OPT["mu_bins"][2] + 1),
            "tnu_edges": np.linspace(*OPT["tnu_bins"][:2], OPT["tnu_bins"][2] + 1),
            "mu_c": OPT["mu_c"], "window": OPT["window"], "b_cut": OPT["b_cut"],
            "bootstrap": OPT["bootstrap"], "level": level, "blocks": blocks, "seed": OPT["seed"],
            "lr_edges": np.linspace(*OPT["lr_bins"][:2], OPT["lr_bins"][2] + 1),
            **{name: OPT[name] for name in ("lr_min", "lr_max", "class_min", "uni_edge")}}


# -- synthetic catalogs ---------------------------------------------------------------------

def synthetic_events(rng, task, n, gridded):
    """n events of one task: times on a 0.25 grid (gridded) or continuous, magnitudes partly on
    the 0.25 grid (edges, mu_c, the b cut, the top edge) and partly continuous (a GR tail)."""
    if gridded:
        t = np.cumsum(rng.integers(0, 5, n) * 0.25)          # includes equal times (T = 0)
    else:
        t = np.cumsum(rng.exponential(0.5, n))
    on_grid = rng.random(n) < 0.4
    tail = rng.random(n) < 0.5
    mu = np.where(on_grid, rng.integers(-6, 30, n) * 0.25,   # -1.5 .. 7.25
                  np.where(tail, 3.0 + rng.exponential(LOG10_E / 0.8, n), rng.uniform(-2.0, 3.0, n)))
    epi = rng.integers(0, N_CHAIN, n)
    if n >= 40:
        # successive large events at distances 3 (= window: a recurrence) and 4 (not), at mu_c
        # exactly and at the b cut exactly
        epi[20:30] = [20, 23, 27, 24, 20, 17, 13, 16, 20, 23]
        mu[20:30] = [4.0, 5.0, 4.0, 4.0, 6.0, 4.0, 5.0, 4.0, 4.0, 5.5]
        mu[30:34] = 3.0
    half = rng.integers(0, 1 + (3 * np.clip(mu, 0, None)).astype(int))
    first, last = np.maximum(epi - half, 0), np.minimum(epi + half, N_CHAIN - 1)
    # zones reaching no end: every third event's epicenter at its zone's right end, every third halfway (no draw,
    # no end reached anew: the streams, and what the recurrences see, stay)
    inside = (first > 0) & (last < N_CHAIN - 1)
    last = np.where(inside, epi + half * (np.arange(n) % 3) // 2, last)
    # stress drops without a draw (the streams stay): rising with the length, a tenth of them unknown (NaN, as an
    # older catalog's)
    drop = np.where(epi % 10 == 3, np.nan, 5.0 + (mu % 1.0) + 0.02 * (last - first + 1))
    # nucleation columns, likewise: some unknown (n_onset 0, as an older catalog's), some without a spread (NaN)
    n_onset = np.where(epi % 7 == 2, 0, 1 + (epi % 3 == 0) * (epi % 5))
    t_spread = np.where(epi % 4 == 1, np.nan, 1.0 + 10.0 * (mu % 1.0))
    t_widest = 2.0 + 10.0 * (mu % 1.0) + 0.1 * (epi % 9)
    n_widest = 1 + (last - first) // 4
    return {"task": np.full(n, task, dtype=np.int64), "t": t, "epicenter": epi.astype(np.int64), "mu": mu,
            "slip": 10.0 ** mu, "first": first.astype(np.int64), "last": last.astype(np.int64),
            "n_slipped": (last - first + 1).astype(np.int64), "boundary": (first == 0) | (last == N_CHAIN - 1),
            "duration": rng.random(n) + 0.1, "kind": np.zeros(n, np.int8), "ending": np.zeros(n, np.int8),
            "stress_drop": drop, "n_onset": n_onset.astype(np.int64), "t_spread": t_spread, "t_widest": t_widest,
            "n_widest": n_widest.astype(np.int64), "across_first": np.zeros(n, np.int64),
            "across_last": np.zeros(n, np.int64)}


def write_catalog(path, config_text, written, seed):
    """A catalog through the project's writer (catalog_writer.write_events): task k gets
    written[k] synthetic events; tasks with all their events are finished, the others left open
    (an empty task never committed). Returns the events (dict of columns, tasks in order)."""
    tasks = task_list(loads(config_text))
    assert len(tasks) == len(written)
    rng = np.random.default_rng(seed)
    parts = [synthetic_events(rng, t.index, written[t.index], gridded=t.index % 2 == 0) for t in tasks]
    write_events(path, config_text, parts)
    return {c: np.concatenate([p[c] for p in parts]) for c in schema.EVENT_FIELDS}


CONFIG = """
[model]
N = {N}
[sweep]
{sweep}
[run]
seeds = {seeds}
events = 400
transient = 5
seed = {seed}
"""
# run.events of each catalog (CONFIG's 400, which test_export and test_options take): 400 where the edges need
# them, fewer where only the count of seeds or tasks matters (the reference's time grows with the square of a
# task's events); below, the events written of each task
EVENTS = {"seeds": 400, "blocks": 400, "pairs": 400, "ten": 100, "more": 200, "whole": 200}
# four points x three seeds: an empty task (never committed), a partly written one, a tiny one
SEEDS_WRITTEN = [400, 400, 400, 400, 0, 250, 400, 400, 3, 400, 137, 400]
# three points x one seed: block bootstrap over stretches, one task shorter than the stretches, one empty
BLOCKS_WRITTEN = [400, 5, 0]
# two points x ten seeds (the fewest that resample seeds), one empty, one short
TEN_WRITTEN = [100, 100, 0, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 100, 15, 100, 100, 100, 100, 100]
# two points x two seeds, one of them empty: the stretches of both are resampled
PAIRS_WRITTEN = [400, 220, 0, 400]
# merged with "ten" (another root seed): point nu = 1 pools with the first point of "ten"
MORE_WRITTEN = [200, 45, 200, 200]
# every task finished (a complete run)
WHOLE_WRITTEN = [200, 200]


@pytest.fixture(scope="module")
def catalogs(tmp_path_factory):
    d = tmp_path_factory.mktemp("reduction")
    made = {}
    for name, sweep, seeds, root, written in (
            ("seeds", "nu = [1.0, 0.5]\nb = [20.0, 30.0]", 3, 0, SEEDS_WRITTEN),
            ("blocks", "nu = [2.0, 1.0, 0.5]", 1, 0, BLOCKS_WRITTEN),
            ("pairs", "nu = [1.0, 2.0]", 2, 0, PAIRS_WRITTEN),
            ("ten", "nu = [1.0, 0.5]", 10, 3, TEN_WRITTEN),
            ("more", "nu = [2.0, 1.0]", 2, 5, MORE_WRITTEN),
            ("whole", "nu = [3.0]", 2, 7, WHOLE_WRITTEN)):
        path = d / f"{name}.h5"
        text = CONFIG.format(N=N_CHAIN, sweep=sweep, seeds=seeds, seed=root).replace(
            "events = 400", f"events = {EVENTS[name]}")
        events = write_catalog(path, text, written, seed=len(name) + root)
        made[name] = (path, events)
    return d, made


# case: (catalog, level, stretches per task)
CASES = {"seeds": ("seeds", 0.95, 4),      # 3 seeds per point: 4 stretches of each task
         "ten_seeds": ("ten", 0.95, 4),    # 10 seeds per point: the tasks are the units
         "blocks": ("blocks", 0.9, 7),     # 1 seed per point: 7 stretches of its trajectory are
         "one_unit": ("blocks", 0.95, 1),  # ... or 1 stretch: a single unit, no intervals
         "two_seeds": ("pairs", 0.8, 3)}   # 2 seeds per point: 3 stretches of each


@pytest.fixture(scope="module")
def references(catalogs):
    """Brute-force expectations of each case (computed once)."""
    _, made = catalogs
    out = {}
    for case, (name, level, blocks) in CASES.items():
        path, events = made[name]
        got, tasks, _ = reader.read(path)
        for c in schema.EVENT_FIELDS:     # the writer stored what was generated
            np.testing.assert_array_equal(got[c], events[c], err_msg=c)
        opt = options(level, blocks)
        out[case] = (path, tasks, opt, ref.expected_summary([(path, events, tasks)], opt))
    return out


def test_catalogs_exercise_the_edges(references):
    """What the comparisons rely on occurs in the data (else a mutation could pass by luck)."""
    _, tasks, opt, exp = references["seeds"]
    raw = exp["raw"]
    mu = np.concatenate([t.mu for t in raw])
    for value in (opt["mu_c"], opt["b_cut"], opt["mu_edges"][0], opt["mu_edges"][-1]):
        assert np.any(mu == value), value
    assert np.any(mu < opt["mu_edges"][0]) and np.any(mu > opt["mu_edges"][-1])
    tnu = np.concatenate([t.tnu for t in raw])
    assert np.any(np.isin(tnu, opt["tnu_edges"][1:-1])) and np.any(tnu == 0) and np.any(tnu > opt["tnu_edges"][-1])
    interior = np.concatenate([t.interior for t in raw])
    assert len(tnu) > 500 and 0.2 < interior.mean() < 0.8
    # the rupture statistics: a finite L_0 with an interval, both classes, at and away from a predecessor's rim
    for name in ("L0", "fraction_unilateral", "uni_at_rim", "bi_at_rim", "mean_slip_large", "slip_ratio",
                 "mean_drop_large", "drop_ratio", "L_sc", "t_initial", "spread_share", "L_c", "t_nucleation"):
        est, lo, hi = exp[f"points/numbers/{name}"].T
        share = name in ("fraction_unilateral", "uni_at_rim", "bi_at_rim", "spread_share")
        assert np.all(np.isfinite(est)) and np.all(lo < hi) and np.all((est > 0) & ((est < 1) | (not share))), name
    # recurrences that straddle chunks of 7 and 13 rows and stretches
    start, end = np.concatenate([t.rec_start for t in raw]), np.concatenate([t.rec_end for t in raw])
    assert np.any(start // 7 != end // 7) and np.any(start // 13 != end // 13)
    assert any(np.any(t.stretch[t.rec_start] != t.stretch[t.rec_end]) for t in raw if len(t.rec_start))
    # the pattern of task 0 (events 20-29): 20 -> 21 at distance 3 = window closes, 21 -> 22 at 4
    # does not (21 is closed by 23 at distance 1), and 22, at mu_c exactly, is closed by 23 at 3
    t0 = raw[0]
    closing = dict(zip(t0.rec_start.tolist(), t0.rec_end.tolist()))
    assert closing[20] == 21 and closing[21] == 23 and closing[22] == 23 and t0.mu[22] == opt["mu_c"]
    # tasks of unequal lengths, some shorter than a stretch count, one empty
    assert {len(t.mu) for t in raw} >= {0, 3, 137, 250, 400}
    # the interior subset differs from all: in mean and mode, in some point
    num = {k: exp[f"points/numbers/{k}"][:, 0] for k in ("mean_tnu", "mean_tnu_interior", "mode_tnu")}
    assert np.any(num["mean_tnu"] != num["mean_tnu_interior"])
    centers = 0.5 * (opt["tnu_edges"][1:] + opt["tnu_edges"][:-1])
    interior_mode = [centers[np.argmax(row)] for row in exp["points/tnu_interior_density"]]
    assert np.any(num["mode_tnu"] != interior_mode)
    # intervals are not degenerate; peaks exist, several with intervals
    b = exp["points/numbers/gr_b"]
    assert np.all(b[:, 2] > b[:, 1])
    assert np.isfinite(exp["points/peaks"][..., 1]).sum() >= 2
    # the one-seed catalog: 7 stretches per point; the 5-event task leaves two empty, the
    # empty task has no numbers at all
    _, _, _, exp_b = references["blocks"]
    assert list(exp_b["points/method"]) == ["blocks"] * 3 and list(exp_b["points/units"]) == [7] * 3
    assert exp_b["points/numbers/n_events"][2, 0] == 0
    assert np.isnan(exp_b["points/numbers/fraction_large"][2]).all()
    # its sparse recurrence histograms meet candidate peaks of equal height (the tie rule)
    assert exp_b["tied"]
    # with one stretch a point has a single unit: estimates without intervals
    _, _, _, exp_1 = references["one_unit"]
    assert list(exp_1["points/units"]) == [1] * 3 and np.isnan(exp_1["points/numbers/gr_b"][:, 1:]).all()
    assert np.isfinite(exp_1["points/numbers/gr_b"][0, 0]) and np.isfinite(exp_1["points/peaks"][0, 0, 0])
    # fewer than ten seeds: the stretches of every task, even of an empty one (2 x 3; 3 x 4)
    _, _, _, exp_2 = references["two_seeds"]
    assert list(exp_2["points/method"]) == ["blocks"] * 2 and list(exp_2["points/units"]) == [6, 6]
    assert np.all(exp_2["points/numbers/n_events"][:, 2] > exp_2["points/numbers/n_events"][:, 1])
    assert list(exp["points/method"]) == ["blocks"] * 4 and list(exp["points/units"]) == [12] * 4
    # ten seeds (one empty, one short): the tasks themselves
    _, _, _, exp_10 = references["ten_seeds"]
    assert list(exp_10["points/method"]) == ["seeds"] * 2 and list(exp_10["points/units"]) == [10, 10]
    assert np.all(exp_10["points/numbers/n_events"][:, 2] > exp_10["points/numbers/n_events"][:, 1])


@pytest.fixture(scope="module")
def summaries(catalogs, references):
    """summary_of(case, chunk): path of the case's summary, reduced (once) in chunks of `chunk` rows."""
    made = {}

    def summary_of(case, chunk):
        if (case, chunk) not in made:
            path, _, opt, exp = references[case]
            out = catalogs[0] / f"{case}_{chunk}.summary.h5"
            res = reduce_here(chunk, path, out, opt["level"], opt["blocks"])
            # reduce warns on stderr for exactly the points with fewer than 10 units
            warned = re.findall(r"^warning: point (\d+) \(.*: intervals unreliable: (\d+) resampling units?",
                                res.stderr, re.M)
            assert warned == [(str(i), str(u)) for i, u in enumerate(exp["points/units"]) if u < 10], res.stderr
            made[case, chunk] = out
        return made[case, chunk]
    return summary_of


@pytest.mark.parametrize("case, chunk", [("seeds", 7), ("blocks", 3), ("one_unit", 1 << 16), ("two_seeds", 64),
                                         ("ten_seeds", 11)])
def test_summary_equals_brute_force(references, summaries, case, chunk):
    """The whole summary, reduced with the catalog streamed in chunks of `chunk` rows."""
    path, tasks, opt, exp = references[case]
    ref.check_summary(ref.read_summary(summaries(case, chunk)), exp, opt)


def test_report_states_every_number_and_the_level(references, summaries):
    """`analysis report`: each number of each point, its interval and the peaks, to the 4 digits
    it prints, and the interval level as given (a 97.5% interval is not "97%")."""
    from analysis import report, summary
    _, _, opt, exp = references["blocks"]
    s = summary.read(summaries("blocks", 3))
    text = report.table(s)
    # the catalog holds unfinished tasks (reduced with --partial): the first line says so
    assert text.splitlines()[0] == s["attrs"]["partial"] != ""
    assert f"90% intervals from {OPT['bootstrap']} bootstrap resamples" in text.splitlines()[1]
    blocks = text.split("\npoint ")[1:]
    assert len(blocks) == 3
    number = r"-?\d+(?:\.\d*)?(?:e[-+]\d+)?|nan"

    def same(printed, values):
        want = [v for v in values if math.isfinite(v)]
        got = [float(x) for x in re.findall(number, printed)]
        assert len(got) == len(want), (printed, values)
        for g, w in zip(got, want):
            assert g == pytest.approx(w, rel=5e-4, abs=0), (printed, values)   # .4g

    for i, block in enumerate(blocks):
        lines = block.splitlines()
        assert "resampling blocks, 7 units" in lines[0]
        # 7 stretches < reduce.MIN_UNITS: the intervals are flagged, saying what is needed
        assert lines[1].strip().startswith("WARNING: intervals unreliable: 7 resampling units (blocks); "
                                           "at least 10 are needed: 10 seeds (run.seeds), or 10 stretches"), lines[1]
        # each line: its label, two spaces, its value (labels and values hold single spaces only)
        printed = dict(line.strip().split("  ", 1) for line in lines[2:] if line.strip())
        for name in ref.NUMBERS + ref.SEISMICITY_NUMBERS:      # every number (the creep's: test_creep_statistics)
            est, lo, hi = exp[f"points/numbers/{name}"][i]
            if math.isfinite(est):
                same(printed[report.LABELS[name]], [est, lo, hi])
            else:
                assert printed[report.LABELS[name]].strip() == "-"
        # the statistics' lines in their order: the recurrence peaks after the recurrence numbers
        labels = list(printed)
        assert labels.index("T*nu peaks") == labels.index(report.LABELS["mean_tnu_interior"]) + 1, labels
        peaks = printed["T*nu peaks"]
        rows = [row for row in exp["points/peaks"][i] if math.isfinite(row[0])]
        assert (peaks.strip() == "-") == (not rows)
        for part, row in zip(peaks.split(";"), rows):
            same(part, row)
    for level, text in ((0.975, "97.5%"), (0.29, "29%"), (0.95, "95%")):
        s["attrs"]["level"] = level
        assert f" {text} intervals" in report.table(s).splitlines()[1]


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
def test_mpi_summary_equals_brute_force(references, catalogs):
    """Two ranks, each reducing its share of the tasks in chunks of 13 rows, merged on rank 0."""
    path, tasks, opt, exp = references["seeds"]
    out = catalogs[0] / "seeds_mpi.summary.h5"
    run(["mpiexec", "-n", "2", *reduce_command(13, path, out, opt["level"], opt["blocks"])])
    ref.check_summary(ref.read_summary(out), exp, opt)


# -- several catalogs, unfinished runs ---------------------------------------------------------

def merged_reference(catalogs, names, level=0.9, blocks=5):
    """(paths, opt, expected summary) of the named synthetic catalogs reduced together."""
    _, made = catalogs
    inputs = []
    for name in names:
        path, events = made[name]
        inputs.append((path, events, reader.read_tasks(path)[1]))
    opt = options(level, blocks)
    return [p for p, _, _ in inputs], opt, ref.expected_summary(inputs, opt)


@pytest.fixture(scope="module")
def merges(catalogs):
    """merge_of(names): (path of the summary of the named catalogs reduced together, reduced once
    in chunks of 13 rows; its options; its expected summary)."""
    made = {}

    def merge_of(names):
        if names not in made:
            paths, opt, exp = merged_reference(catalogs, names)
            out = catalogs[0] / ("-".join(names) + ".summary.h5")
            reduce_here(13, paths, out, opt["level"], opt["blocks"])
            made[names] = out, opt, exp
        return made[names]
    return merge_of


@pytest.mark.parametrize("names", [("ten", "more"), ("more", "ten")])
def test_merged_catalogs_equal_brute_force(merges, names):
    """Two catalogs (root seeds 3 and 5) reduced together: point (nu = 1, b = 20) pools ten
    tasks of one with two of the other, the other points stand side by side in the order of
    first appearance; every dataset against the reference, in both orders of the catalogs.
    (Stretches of tasks of two catalogs pooled: test_mpi_merge_equals_brute_force, and
    test_analysis.py's merged catalogs.)"""
    out, opt, exp = merges(names)
    pooled = [i for i in range(len(exp["points/nu"])) if exp["points/nu"][i] == 1.0 and exp["points/b"][i] == 20.0]
    # twelve tasks, at least ten: the tasks are the units (in the order of their streams); the point nu = 2
    # of "more" alone has two: 5 stretches of each
    assert len(pooled) == 1 and len(exp["points/nu"]) == 3
    assert exp["points/units"][pooled[0]] == 12 and list(exp["points/method"]).count("blocks") == 1
    ref.check_summary(ref.read_summary(out), exp, opt)


def test_a_point_does_not_depend_on_the_order_of_the_catalogs(merges):
    """The pooled point's tasks, streams, numbers, curves, intervals and peaks are the same
    whichever catalog comes first (its units in stream order, its bootstrap keyed on its
    parameters), though it is point 0 in one summary and point 1 in the other."""
    one, two = (ref.read_summary(merges(names)[0]) for names in (("ten", "more"), ("more", "ten")))

    def pooled(s):
        return int(np.flatnonzero((s["points/nu"] == 1.0) & (s["points/b"] == 20.0))[0])
    i, j = pooled(one), pooled(two)
    assert (i, j) == (0, 1)
    keys = [k for k in one if k.startswith("points/") and k not in ("points/method", "points/units")]
    assert len(keys) > 20
    for key in keys:
        np.testing.assert_array_equal(one[key][i], two[key][j], err_msg=key)
    streams = [sorted(zip(s["tasks/seed_entropy"][s["tasks/point"] == p], s["tasks/spawn_key"][s["tasks/point"] == p]))
               for s, p in ((one, i), (two, j))]
    assert streams[0] == streams[1] == [(3, k) for k in range(10)] + [(5, 2), (5, 3)]


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
def test_mpi_merge_equals_brute_force(catalogs):
    """Two ranks split the tasks of three catalogs (each rank reads tasks of every catalog);
    points nu = 2 and nu = 1 pool a task of "blocks" with two of "more"."""
    paths, opt, exp = merged_reference(catalogs, ("blocks", "more", "whole"), level=0.95, blocks=3)
    assert list(exp["points/units"]) == [9, 9, 3, 6]     # 3 stretches of each of 3, 3, 1, 2 tasks
    out = catalogs[0] / "three_mpi.summary.h5"
    run(["mpiexec", "-n", "2", *reduce_command(29, paths, out, opt["level"], opt["blocks"])])
    ref.check_summary(ref.read_summary(out), exp, opt)


def test_the_same_trajectory_twice_is_refused(catalogs):
    """"pairs" has the root seed of "seeds" and its point nu = 1, b = 20: tasks 0 and 1 of both are
    the same trajectories. Refused before any work, one line naming both; so is a catalog given twice."""
    d, made = catalogs
    seeds, pairs = str(made["seeds"][0]), str(made["pairs"][0])
    for paths, words in (([seeds, pairs], f"{seeds} task 0 and {pairs} task 0 are the same trajectory "
                                         "(seed_entropy 0, spawn_key 0, N = 40, l = 3, nu = 1, a = 0, b = 20, "
                                         "c = 1000): give each trajectory once"),
                         ([seeds, f"{d}/./seeds.h5"], f"{d}/./seeds.h5 is given twice (also as {seeds}): "
                                                      "give each catalog once")):
        out = d / "refused.summary.h5"
        res = reduce_here(64, paths, out, 0.95, 3, check=False)
        lines = res.stderr.strip().splitlines()
        assert res.returncode == 2 and lines == [f"error: {words}"], res.stderr
        assert not out.exists() and not res.stdout


def test_unfinished_runs_need_partial_and_say_so(catalogs):
    """A catalog with unfinished tasks, or named *.partial, is refused (exit 1, one line) unless
    --partial is given; then the summary's `partial` attribute (checked against the reference by
    every test here) says how many events of how many and which catalogs, and so do the report's
    first line and the figure titles. A complete run needs no --partial and says nothing."""
    from analysis import plot, report, summary
    d, made = catalogs
    whole = made["whole"][0]
    named = shutil.copy(whole, d / "whole2.h5.partial")    # every task finished, name unfinished
    for path, what in ((made["pairs"][0], "2 of 4 tasks unfinished"), (named, "named *.partial")):
        res = reduce_here(64, path, d / "x.summary.h5", 0.95, 3, partial=False, check=False)
        assert res.returncode == 1 and res.stderr.strip().splitlines() == [
            f"error: {path} is an unfinished run ({what}); continue it with `python -m ensemble resume "
            f"{str(path).removesuffix('.partial')}`, or reduce what it holds with --partial"], res.stderr
        assert not (d / "x.summary.h5").exists()
    # with --partial: both reduced as far as written; the statement names them
    paths = [made["pairs"][0], named]
    opt = options(0.9, 5)
    exp = ref.expected_summary([(p, *reader.read(p)[:2]) for p in paths], opt)
    written = sum(PAIRS_WRITTEN) + sum(WHOLE_WRITTEN)
    expected = len(PAIRS_WRITTEN) * EVENTS["pairs"] + len(WHOLE_WRITTEN) * EVENTS["whole"]
    assert exp["partial"] == (written, expected, [str(p) for p in paths])
    out = d / "partial.summary.h5"
    res = reduce_here(64, paths, out, opt["level"], opt["blocks"])
    ref.check_summary(ref.read_summary(out), exp, opt)
    s = summary.read(out)
    statement = s["attrs"]["partial"]
    head = f"PARTIAL reduction of unfinished runs: {written} of {expected} events ({100 * written / expected:.1f}%)"
    assert statement == f"{head}; {paths[0]} (2 of 4 tasks unfinished), {named} (all tasks finished)"
    assert res.stdout.splitlines()[0] == statement
    assert report.table(s).splitlines()[0] == statement
    assert plot.title_text([s], ["partial"]).splitlines()[1] == head
    # a complete run: no --partial needed, nothing said
    out = d / "whole.summary.h5"
    res = reduce_here(64, whole, out, 0.95, 3, partial=False)
    assert res.returncode == 0, res.stderr
    s = summary.read(out)
    assert s["attrs"]["partial"] == "" and not report.table(s).startswith("PARTIAL")
    assert len(plot.title_text([s], ["whole"]).splitlines()) == 1


def test_peak_finder_follows_its_documented_rule():
    """stats.find_peaks against the plain transcription of its rule (reference.PEAK_RULE) on
    sparse random histograms (many with plateaus, where the tie rule decides) and noise levels
    around the prominences, so that the threshold decides too."""
    rng = np.random.default_rng(8)
    ties = kept = dropped = 0
    for _ in range(3000):
        n = int(rng.integers(2, 60))
        counts = rng.poisson(rng.uniform(0.05, 3.0), n) * (rng.random(n) < 0.7)
        edges = np.linspace(0.0, 2.0 * n, n + 1)
        noise = rng.uniform(0.0, 0.3, n) * rng.uniform(0.0, 2.0)
        ties += ref.tied_peaks(counts)
        found = list(stats.find_peaks(counts, edges, noise))
        assert found == ref.plain_peaks(counts, edges, noise), counts
        kept += len(found)
        dropped += len(ref.plain_peaks(counts, edges, np.zeros(n))) - len(found)
    assert ties > 100 and kept > 1000 and dropped > 1000


def test_prominence_is_scipys():
    """stats.prominence equals scipy.signal.peak_prominences (the definition it cites) at every
    local maximum of random tie-free sequences."""
    signal = pytest.importorskip("scipy.signal", reason="scipy (the test extra) checks the definition")
    rng = np.random.default_rng(4)
    for _ in range(300):
        s = np.concatenate([[0.0], rng.random(int(rng.integers(3, 40))), [0.0]])
        peaks, _ = signal.find_peaks(s)
        prom, left, right = signal.peak_prominences(s, peaks)
        for p, want, lb, rb in zip(peaks, prom, left, right):
            got, base = stats.prominence(s, p)
            assert got == want and base == (lb if s[lb] >= s[rb] else rb)


@pytest.mark.parametrize("case", range(40))
def test_peak_finder_reports_the_true_peaks_and_no_spurious_ones(case):
    """Synthetic recurrence histograms with known peaks (0, 1 or 2 Gaussians or an exponential
    falling from T = 0, on a smooth background) and sampling noise, split into 20 seeds as a run
    would be, through the reduction's own peak step: exactly the true peaks, each within one bin
    and with an interval around it. The threshold (3 noise standard deviations) was chosen on such
    data: at 2 about 2-9% of histograms gained a spurious peak, at 3 and 4 none of 600."""
    from analysis.statistics.recurrence import peaks
    rng = np.random.default_rng(100 + case)
    edges = np.linspace(0.0, 2000.0, 81)
    shapes = [[], [(600.0, 80.0)], [(400.0, 60.0), (1300.0, 100.0)], "exponential"]
    shape = shapes[case % 4]
    n = int(rng.choice([800, 3000, 20000]))
    units = []
    for _ in range(20):
        if shape == "exponential":
            x = rng.exponential(300.0, n // 20)
        elif shape:
            which = rng.integers(0, len(shape), n // 20)
            x = rng.normal([shape[w][0] for w in which], [shape[w][1] for w in which])
        else:
            x = rng.gamma(3.0, 250.0, n // 20)    # one broad maximum near 500
        units.append(np.histogram(x, edges)[0])
    opt = reduce_options.make(mu_bins="0:7:70", tnu_bins=edges, bootstrap=300, mu_c=4.0, b_cut=3.0)
    rows = peaks({"tnu": np.array(units)}, opt, rng)["peaks"]
    # true positions, and how far a histogram's maximum may stray: 1.5 bins, or 0.3 standard
    # deviations of a broad peak (the gamma's sd is 433; its maximum is found up to ~90 away)
    truth = ([(12.5, 0)] if shape == "exponential" else shape if shape else [(500.0, 433.0)])
    assert len(rows) == len(truth), rows
    width = edges[1] - edges[0]
    for (pos, lo, hi), (true, sd) in zip(sorted(rows.tolist()), sorted(truth)):
        assert abs(pos - true) <= max(1.5 * width, 0.3 * sd) and lo <= pos <= hi, rows


# -- the interval's level --------------------------------------------------------------------

@pytest.mark.parametrize("level", [0.95, 0.9, 0.5])
def test_percentile_interval_leaves_the_documented_share_outside(level):
    """lo and hi are the (1 - level) / 2 and (1 + level) / 2 quantiles along axis 0, NaNs left out:
    of n distinct samples, the share strictly below lo (above hi) is (1 - level) / 2 to within 1 / n
    (a 97.5% interval called 95% leaves 1.25% outside: 50 samples of 4000 off)."""
    rng = np.random.default_rng(3)
    n = 4000
    samples = rng.normal(size=(n + 300, 3))
    samples[rng.permutation(n + 300)[:300], 1] = np.nan       # NaNs in one column only
    lo, hi = stats.percentile_interval(samples, level)
    tail = (1 - level) / 2
    for j in range(3):
        x = samples[:, j]
        x = x[np.isfinite(x)]
        assert abs(np.mean(x < lo[j]) - tail) <= 1 / len(x)
        assert abs(np.mean(x > hi[j]) - tail) <= 1 / len(x)
        assert lo[j] == pytest.approx(ref.percentile(list(x), 100 * tail), rel=1e-12)
        assert hi[j] == pytest.approx(ref.percentile(list(x), 100 * (1 - tail)), rel=1e-12)


def test_percentile_bootstrap_covers_at_its_exact_level():
    """stats.bootstrap and stats.percentile_interval, for the mean of R = 4000 independent normal
    samples of n = 200 units each, with 1000 resamples: the coverage must be the 95% interval's,
    tightly enough that a 97.5% (or a 90%) interval labelled 95% fails.

    With n = 200 the percentile interval of a mean is xbar +- z s_n / sqrt(n) (s_n the plug-in
    standard deviation), so its exact coverage is P(|t_{n-1}| <= z sqrt((n - 1) / n)): 0.9480 for
    the 95% interval, 0.9735 for a 97.5% one (z = 2.2414) and 0.8976 for a 90% one. The binomial
    standard error of a rate over R = 4000 replications is sqrt(0.95 * 0.05 / 4000) = 0.0034
    (0.0025 at 0.975); 1000 resamples lower the coverage by about 0.001 (seeds 12-16 gave
    0.9445-0.9505, and 0.9700-0.9765 for the 97.5% interval). The window exact +- 0.012 is
    3.5 standard errors wide each side: a correct interval passes, a 97.5% one called 95% misses
    it by 5 of its standard errors (0.9735 - 0.960 = 0.0135), a 90% one by 11.
    """
    from scipy import stats as sps
    n, replications, resamples = 200, 4000, 1000
    rng = np.random.default_rng(12)
    x = rng.normal(size=(n, replications))
    # units: one row per unit, (count, value) per replication; the statistic is the mean of
    # each replication (vectorised: every resample applies to all replications at once, which
    # leaves the replications independent given the picks)
    units = np.stack([np.ones_like(x), x], axis=1)
    samples = stats.bootstrap(units, lambda s: s[1] / s[0], resamples, rng)
    lo, hi = stats.percentile_interval(samples, 0.95)
    rate = np.mean((lo <= 0.0) & (0.0 <= hi))
    exact = 1 - 2 * sps.t.sf(sps.norm.ppf(0.975) * math.sqrt((n - 1) / n), n - 1)
    print(f"coverage of the 95% percentile interval: {rate:.4f} (exact {exact:.4f})")
    assert abs(exact - 0.9480) < 1e-4
    assert abs(rate - exact) <= 0.012
