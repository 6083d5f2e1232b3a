"""Reduction: merged histograms, recurrence times, bootstrap coverage, GR b, serial vs MPI;
several catalogs reduced together; figures of several summaries.

The real catalog is reduced once by `python -m analysis reduce` and once under `mpiexec -n 2`; the
other commands run in this process (analysis.cli.main, which `python -m analysis` calls): a process
of its own costs about 2.5 s of imports, more than the command's work on these catalogs."""
import dataclasses
import shutil
import sys

import numpy as np
import pytest

from analysis import stats, summary
from analysis.recurrence import RecurrenceScanner
from ensemble.store import reader
from ensemble.config import loads

from . import reduction_reference as ref
from .catalog_writer import write_events
from .conftest import run_cli, write_config
from .processes import analysis_here, run_bounded


# bootstrap resamples of the real catalog's reductions: the comparisons with the reference are exact
# (the same resamples), so a hundred see as much as more would
BOOTSTRAP = "100"


def run_analysis(*args):
    return run_bounded([sys.executable, "-m", "analysis", *args], 300)


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """A real catalog (2 points x 2 seeds x 150 events, N = 60) and its summary."""
    d = tmp_path_factory.mktemp("analysis")
    cfg = write_config(d / "cfg.toml", sweep={"b": [20.0, 30.0]}, run={"seeds": 2, "events": 150, "transient": 50},
                       integrator={"dt": 5e-4})
    assert run_cli("run", cfg, "-o", d / "cat.h5").returncode == 0
    res = run_analysis("reduce", d / "cat.h5", "-o", d / "sum.h5", "--bootstrap", BOOTSTRAP, "--mu-c", "3.5")
    assert res.returncode == 0, res.stderr
    # two seeds per point, fewer than ten: 20 stretches of each are the units, enough for no warning
    assert "warning" not in res.stderr, res.stderr
    return d


def brute_force_recurrence(t, epi, mu, boundary, mu_c, window):
    """O(n^2) reference: for each large event the first later large event within the window."""
    out = []
    large = np.flatnonzero(mu >= mu_c)
    for a, i in enumerate(large):
        for j in large[a + 1:]:
            if abs(epi[j] - epi[i]) <= window:
                out.append((i, t[j] - t[i], not boundary[i]))
                break
    return sorted(out)


def test_merged_histograms_equal_histogram_of_pooled_events(reduced):
    events, tasks, _ = reader.read(reduced / "cat.h5")
    s = summary.read(reduced / "sum.h5")
    edges = s["bins/mu"]
    for point in (0, 1):
        mine = np.isin(events["task"], np.flatnonzero(tasks["point"] == point))
        pooled, _ = np.histogram(events["mu"][mine], bins=edges)
        merged = s["per_task/mu"][tasks["point"] == point].sum(axis=(0, 1))
        np.testing.assert_array_equal(merged, pooled)
        np.testing.assert_allclose(s["points/mu_density"][point],
                                   pooled / (np.count_nonzero(mine) * np.diff(edges)))
        # the recurrence histogram covers exactly the brute-force recurrence times
        tnu = []
        for k in np.flatnonzero(tasks["point"] == point):
            e = events["task"] == k
            rec = brute_force_recurrence(events["t"][e], events["epicenter"][e], events["mu"][e],
                                         events["boundary"][e], 3.5, 10)
            tnu += [T * 1e-8 for _, T, _ in rec]
        pooled_t, _ = np.histogram(tnu, bins=s["bins/tnu"])
        np.testing.assert_array_equal(s["per_task/tnu"][tasks["point"] == point].sum(axis=(0, 1)), pooled_t)
        assert s["points/numbers/n_recurrences"][point][0] == len(tnu) > 10


def test_real_summary_equals_brute_force(reduced):
    """Every dataset of the real catalog's summary (and so of its 2-rank twin, which
    test_serial_and_mpi_reduction_agree finds identical) against the plain reference."""
    events, tasks, _ = reader.read(reduced / "cat.h5")
    opt = {"mu_edges": np.linspace(0, 7, 71), "tnu_edges": np.linspace(0, 2000, 81), "mu_c": 3.5,
           "window": 10, "b_cut": 3.0, "bootstrap": int(BOOTSTRAP), "level": 0.95, "blocks": 20, "seed": 0}
    expected = ref.expected_summary([(reduced / "cat.h5", events, tasks)], opt)
    assert expected["points/numbers/n_recurrences"][:, 0].min() > 10
    ref.check_summary(ref.read_summary(reduced / "sum.h5"), expected, opt)


@pytest.mark.parametrize("chunk", [1, 7, 10000])
def test_recurrence_scan_matches_brute_force(chunk):
    """Synthetic catalog with epicenters exactly at the window edge and an interior filter."""
    rng = np.random.default_rng(5)
    n, window = 3000, 10
    t = np.cumsum(rng.exponential(1.0, n))
    epi = rng.integers(0, 200, n)
    epi[100:110] = [50, 60, 71, 61, 50, 40, 29, 39, 50, 61]   # distances 10 (in) and 11 (out)
    mu = rng.uniform(0, 6, n)
    mu[100:110] = 5.0
    boundary = rng.random(n) < 0.3
    expected = brute_force_recurrence(t, epi, mu, boundary, 4.0, window)
    scanner = RecurrenceScanner(200, 4.0, window)
    got = []
    for lo in range(0, n, chunk):
        src, T, interior = scanner.feed(t[lo:lo + chunk], epi[lo:lo + chunk], mu[lo:lo + chunk],
                                        boundary[lo:lo + chunk])
        got += list(zip(src.tolist(), T.tolist(), interior.tolist()))
    got.sort()
    assert [g[0] for g in got] == [e[0] for e in expected]
    np.testing.assert_allclose([g[1] for g in got], [e[1] for e in expected], rtol=1e-12)
    assert [g[2] for g in got] == [e[2] for e in expected]
    pairs = dict((g[0], g[1]) for g in got)
    assert pairs[100] == pytest.approx(t[101] - t[100])      # |60 - 50| = 10: inside
    assert pairs[102] == pytest.approx(t[103] - t[102])      # |61 - 71| = 10: inside
    assert pairs[101] == pytest.approx(t[103] - t[101])      # 102 at |71 - 60| = 11 is outside


def test_bootstrap_interval_covers_truth_at_nominal_rate():
    """Mean of exponential data from 20 independent seeds: the 95% interval covers 1 about 95% of the time."""
    rng = np.random.default_rng(2)
    trials, covered = 400, 0
    for _ in range(trials):
        units = np.array([[30, rng.exponential(1.0, 30).sum()] for _ in range(20)])
        samples = stats.bootstrap(units, lambda s: s[1] / s[0], 400, rng)
        lo, hi = stats.percentile_interval(samples, 0.95)
        covered += lo <= 1.0 <= hi
    rate = covered / trials
    print(f"bootstrap coverage of the nominal 95% interval: {rate:.3f}")
    # the percentile bootstrap under-covers a little with 20 units (about 0.93); the binomial
    # standard deviation of the measured rate is 0.012. This window is too wide to tell a 97.5%
    # interval from a 95% one: test_reduction.py checks the exact level
    assert 0.90 <= rate <= 0.98


def test_b_value_recovers_known_gutenberg_richter():
    rng = np.random.default_rng(4)
    for b_true in (0.5, 1.0, 1.5):
        mu = 3.0 + rng.exponential(np.log10(np.e) / b_true, 20000)
        b = stats.gr_b(len(mu), mu.sum(), 3.0)
        assert abs(b - b_true) < 3 * b_true / np.sqrt(len(mu))
        counts, edges = np.histogram(mu, bins=np.linspace(3, 8, 51))
        assert stats.gr_ks_distance(counts, edges, 3.0, b) < 0.02        # fits a GR law
        assert stats.gr_ks_distance(counts, edges, 3.0, 2 * b) > 0.2     # and not a wrong one


def test_gr_b_standard_error_is_the_spread_of_gr_b_over_independent_catalogs():
    """Shi-Bolt's standard error against the standard deviation of GR b over 400 independent
    catalogs of 500 Gutenberg-Richter magnitudes (b = 0.8): that standard deviation is itself
    known to 3.5% (1 / sqrt(2 * 399)); measured ratio 0.99; a standard error off by a factor
    log10(e) or sqrt(2) falls far outside 0.9-1.1."""
    rng = np.random.default_rng(5)
    b, se = [], []
    for _ in range(400):
        mu = 3.0 + rng.exponential(np.log10(np.e) / 0.8, 500)
        b.append(stats.gr_b(len(mu), mu.sum(), 3.0))
        se.append(stats.gr_b_standard_error(len(mu), mu.sum(), (mu ** 2).sum(), 3.0))
    ratio = np.mean(se) / np.std(b, ddof=1)
    print(f"mean standard error / spread of GR b: {ratio:.3f}")
    assert 0.9 < ratio < 1.1


def test_single_seed_uses_block_bootstrap_and_says_so(tmp_path):
    cfg = write_config(tmp_path / "c.toml", run={"seeds": 1, "events": 200, "transient": 20})
    assert run_cli("run", cfg, "-o", tmp_path / "one.h5").returncode == 0
    res = analysis_here("reduce", tmp_path / "one.h5", "--bootstrap", "50", "--blocks", "10")
    assert res.returncode == 0, res.stderr
    assert "block bootstrap" in res.stdout
    s = summary.read(tmp_path / "one.summary.h5")
    assert list(s["points/method"]) == ["blocks"] and s["points/units"][0] == 10
    lo, hi = s["points/numbers/fraction_large"][0][1:]
    assert lo < hi


def test_report_and_figures(reduced):
    res = analysis_here("report", reduced / "sum.h5")
    assert res.returncode == 0 and "b = 20" in res.stdout and "GR b" in res.stdout
    for fig in ("magnitude", "recurrence"):
        out = reduced / f"{fig}.png"
        res = analysis_here("plot", reduced / "sum.h5", "--figure", fig, "-o", out)
        assert res.returncode == 0, res.stderr
        assert out.stat().st_size > 10000
    # the exit code and message of the command itself, in a process of its own
    res = run_analysis("reduce", reduced / "cat.h5", "-o", reduced / "sum.h5")
    assert res.returncode == 2 and "--force" in res.stderr   # a usage error, as in `ensemble run`
    res = analysis_here("reduce", reduced / "cat.h5", "--mu-bins", "3:1:5", "-o", reduced / "x.h5")
    assert res.returncode == 2 and "bins" in res.stderr


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
def test_serial_and_mpi_reduction_agree(reduced):
    res = run_bounded(["mpiexec", "-n", "2", sys.executable, "-m", "analysis", "reduce", reduced / "cat.h5",
                       "-o", reduced / "sum_mpi.h5", "--bootstrap", BOOTSTRAP, "--mu-c", "3.5"], 300)
    assert res.returncode == 0, res.stderr
    a, b = summary.read(reduced / "sum.h5"), summary.read(reduced / "sum_mpi.h5")
    assert set(a) == set(b)
    for key in a:
        if key != "attrs":
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)


# -- several catalogs ----------------------------------------------------------------------

# The catalogs A and B hold exactly the four trajectories of the real catalog cat.h5 (b = 20, 30
# x 2 seeds, root seed 0: task k has the stream (0, k)). The runner cannot write them: a run's
# tasks are numbered from 0, so two runs with one root seed both hold stream (0, 0), and runs with
# two root seeds cannot be one catalog. So they are written through the catalog writer from the
# real run's events, each task with the stream (provenance) of the task it comes from: A from a
# sweep b = [20, 30] with one seed (tasks 0 and 3 of cat.h5), B from b = [30, 20] (tasks 2 and 1).
SPLIT = {"A": ((20.0, 30.0), (0, 3)), "B": ((30.0, 20.0), (2, 1))}
# level 0.5: quartiles of the resamples are less settled than 95% bounds, so the comparisons see
# the order of the units (20 stretches of each of a point's two tasks) and the bootstrap's stream
REDUCE_OPTIONS = ("--bootstrap", BOOTSTRAP, "--mu-c", "3.5", "--level", "0.5")


@pytest.fixture(scope="module")
def merged(reduced):
    events, tasks, attrs = reader.read(reduced / "cat.h5")
    cfg = loads(attrs["config"])
    for name, (b_values, source) in SPLIT.items():
        text = dataclasses.replace(cfg, sweep=(("b", b_values),),
                                   run=dataclasses.replace(cfg.run, seeds=1)).to_toml()
        parts = []
        for k, task in enumerate(source):
            assert tasks["b"][task] == b_values[k]
            mine = events["task"] == task
            parts.append({c: np.full(mine.sum(), k) if c == "task" else events[c][mine] for c in events})
        write_events(reduced / f"{name}.h5", text, parts, [(0, task) for task in source])
    for names, paths in (("whole", ["cat.h5"]), ("AB", ["A.h5", "B.h5"]), ("BA", ["B.h5", "A.h5"])):
        res = analysis_here("reduce", *(reduced / p for p in paths), "-o", reduced / f"{names}.summary.h5",
                            *REDUCE_OPTIONS)
        assert res.returncode == 0, res.stderr
    return reduced


def test_merged_catalogs_equal_one_catalog_of_both(merged):
    """Every curve, number, interval and peak of each point, and every per-task array and task
    column of each trajectory: A + B (and B + A, whose points come in the other order) equal the
    catalog that holds all four."""
    whole = summary.read(merged / "whole.summary.h5")
    keys = [k for k in whole if k.startswith("points/")]
    assert len(keys) > 20
    for names in ("AB", "BA"):
        s = summary.read(merged / f"{names}.summary.h5")
        assert sorted(s) == sorted(whole)
        first = SPLIT[names[0]][0][0]
        assert list(s["points/b"]) == [first, 50.0 - first]     # first appearance
        for i, b in enumerate(whole["points/b"]):
            j = int(np.flatnonzero(s["points/b"] == b)[0])
            for key in keys:
                np.testing.assert_array_equal(s[key][j], whole[key][i], err_msg=f"{names} {key}")
        assert list(s["attrs"]["catalogs"]) == [str(merged / f"{n}.h5") for n in names]
        assert list(s["tasks/catalog"]) == [0, 0, 1, 1] and list(s["tasks/catalog_task"]) == [0, 1, 0, 1]
        for r in range(4):
            q = int(np.flatnonzero((whole["tasks/spawn_key"] == s["tasks/spawn_key"][r])
                                   & (whole["tasks/b"] == s["tasks/b"][r]))[0])
            for key in ("per_task/mu", "per_task/tnu", "per_task/tnu_interior", "per_task/numbers"):
                np.testing.assert_array_equal(s[key][r], whole[key][q], err_msg=f"{names} {key}")
            for key in ("N", "l", "nu", "a", "b", "c", "events_written", "events_done", "status", "seed_entropy"):
                assert s[f"tasks/{key}"][r] == whole[f"tasks/{key}"][q], key
            assert s["points/b"][s["tasks/point"][r]] == whole["points/b"][whole["tasks/point"][q]]


def test_merged_summary_equals_brute_force(merged):
    """The merged summary against the reference (pooling, task order and bootstrap streams as
    documented), from the catalogs' own events."""
    inputs = [(merged / f"{n}.h5", *reader.read(merged / f"{n}.h5")[:2]) for n in "AB"]
    opt = {"mu_edges": np.linspace(0, 7, 71), "tnu_edges": np.linspace(0, 2000, 81), "mu_c": 3.5,
           "window": 10, "b_cut": 3.0, "bootstrap": int(BOOTSTRAP), "level": 0.5, "blocks": 20, "seed": 0}
    expected = ref.expected_summary(inputs, opt)
    assert list(expected["points/units"]) == [40, 40]     # 20 stretches of each of two tasks
    ref.check_summary(ref.read_summary(merged / "AB.summary.h5"), expected, opt)


def test_merging_a_catalog_with_itself_or_its_trajectories_is_refused(merged):
    for paths, words in (((merged / "A.h5", merged / "cat.h5"),
                          f"{merged / 'A.h5'} task 0 and {merged / 'cat.h5'} task 0 are the same trajectory"),
                         ((merged / "cat.h5", merged / "B.h5"),
                          f"{merged / 'cat.h5'} task 1 and {merged / 'B.h5'} task 1 are the same trajectory"),
                         ((merged / "A.h5", merged / "A.h5"), f"{merged / 'A.h5'} is given twice")):
        res = analysis_here("reduce", *paths, "-o", merged / "dup.summary.h5")
        assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
        assert res.stderr.startswith(f"error: {words}")
        assert not (merged / "dup.summary.h5").exists()
    res = analysis_here("reduce", merged / "A.h5", merged / "B.h5")
    assert res.returncode == 2 and "give its path with -o" in res.stderr


# -- figures of several summaries ----------------------------------------------------------

def fake_summary(**params):
    """The point parameters of a summary (all that legend_labels reads)."""
    n = len(next(iter(params.values())))
    base = {"N": 800, "l": 3.0, "nu": 1e-8, "a": 0.0, "b": 20.0, "c": 1000.0, "alpha": np.nan, "sigma": np.nan}
    return {f"points/{k}": np.array(params.get(k, [v] * n)) for k, v in base.items()}


def test_legend_labels_name_what_differs_between_the_plotted_points():
    from analysis.plot import legend_labels
    one = fake_summary(b=[20.0, 30.0])
    two = fake_summary(N=[1600, 800], b=[40.0, 20.0])
    assert legend_labels([one]) == (["b"], ["b = 20", "b = 30"])
    # N varies only across the summaries; the point in both gets its summary's name
    assert legend_labels([one, two], ["one", "two"]) == (
        ["N", "b"], ["N = 800, b = 20 (one)", "N = 800, b = 30", "N = 1600, b = 40", "N = 800, b = 20 (two)"])
    assert legend_labels([fake_summary(a=[10.0]), fake_summary(a=[20.0], nu=[1e-6])], ["x", "y"]) == (
        ["nu", "a"], ["nu = 1e-08, a = 10", "nu = 1e-06, a = 20"])
    # nothing differs: b names the points; six digits that cannot tell two points apart: all digits
    assert legend_labels([fake_summary(b=[20.0])]) == (["b"], ["b = 20"])
    assert legend_labels([fake_summary(b=[20.0000001, 20.0000002])])[1] == ["b = 20.0000001", "b = 20.0000002"]
    # two friction laws: each point is named by its law and its own law's keys (the other law's are NaN)
    cl = fake_summary(a=[np.nan], b=[np.nan], c=[np.nan], alpha=[2.0], sigma=[0.01])
    assert legend_labels([fake_summary(b=[20.0]), cl]) == (
        ["a", "b", "c", "alpha", "sigma"],
        ["aging: a = 0, b = 20, c = 1000", "carlson-langer: alpha = 2, sigma = 0.01"])
    # two laws with the same keys (aging and slip): only the law tells the points apart
    slip = fake_summary(b=[20.0])
    slip["points/law"] = np.array(["slip"])
    assert legend_labels([fake_summary(b=[20.0]), slip])[1] == ["aging: b = 20", "slip: b = 20"]


def test_plot_overlays_several_summaries(merged):
    for fig in ("magnitude", "recurrence"):
        out = merged / f"overlay-{fig}.png"
        res = analysis_here("plot", merged / "sum.h5", merged / "BA.summary.h5", "--figure", fig, "-o", out)
        assert res.returncode == 0, res.stderr
        assert out.stat().st_size > 10000
