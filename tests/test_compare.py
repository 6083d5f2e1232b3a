"""The friction-law comparison (analysis/compare.py): its estimators on known answers, then the
command on small runs of both laws, checked against the catalogs' events directly.

The runs are processes of their own (`python -m ensemble run`); the analysis commands run in this
process (analysis.cli.main, which `python -m analysis` calls), but one that checks the exit code and
message of the command itself: a process costs about 2.5 s of imports, more than the work here."""
import json
import math
import sys

import numpy as np
import pytest

from analysis import compare as cmp
from analysis import options
from ensemble.store import reader, schema

from .conftest import run_cli, write_config
from .processes import analysis_here, child_env, run_bounded
from .test_laws import write_cl_config


def power_law_counts(tau, n_max, total=10 ** 9):
    """Expected counts per n (index n, 0 unused) of P(n) ~ n^-tau on 1..n_max, rounded."""
    n = np.arange(1, n_max + 1, dtype=float)
    w = n ** -tau
    return np.concatenate([[0], np.round(total * w / w.sum())]).astype(np.int64)


# -- estimators ---------------------------------------------------------------------------------

@pytest.mark.parametrize("tau", [1.5, 2.0, 3.2])
def test_power_law_fit_recovers_the_exponent(tau):
    """From the law's expected counts the fit is exact up to rounding; from a sample of 2e5
    events, within 4 standard errors (1 / sqrt(n Var(ln n)), the Fisher information)."""
    counts = power_law_counts(tau, 800)
    assert cmp.power_law_tau(counts, 1, 50) == pytest.approx(tau, abs=1e-6)
    assert cmp.power_law_ks(counts, 1, tau) < 1e-6
    rng = np.random.default_rng(3)
    n = np.arange(1, 801)
    p = n ** -tau / (n ** -tau).sum()
    sample = np.bincount(rng.choice(n, size=200_000, p=p), minlength=801)
    small = sample[1:50]
    lnn = np.log(np.arange(1, 50))
    var = (small * lnn ** 2).sum() / small.sum() - ((small * lnn).sum() / small.sum()) ** 2
    se = 1 / math.sqrt(small.sum() * var)
    assert abs(cmp.power_law_tau(sample, 1, 50) - tau) < 4 * se


def test_power_law_ks_sees_a_hump_of_large_events():
    """A power law with 10% of the events moved into a hump at n = 300: the KS distance is about
    those 10% (the CDF below the hump misses them), and the fit below n = 50 is unchanged."""
    law = power_law_counts(2.0, 800)
    humped = (0.9 * law).astype(np.int64)
    humped[300] += law.sum() - humped.sum()
    assert cmp.power_law_tau(humped, 1, 50) == pytest.approx(2.0, abs=1e-6)
    assert cmp.power_law_ks(humped, 1, 2.0) == pytest.approx(0.1, abs=0.01)


def test_size_density_is_a_density_in_log10_n():
    """R(log10 n) integrates to 1 over log10 n, and a power law n^-tau becomes n^(1 - tau)."""
    edges = cmp.log_bins(800)
    assert edges[0] == 1 and edges[-1] == 801 and np.all(np.diff(edges) >= 1)
    counts = power_law_counts(2.5, 800)
    density = cmp.size_density(counts, edges)
    share = 1.0 / (np.arange(1, 801) * math.log(10.0))
    widths = np.add.reduceat(share, edges[:-1] - 1)
    assert (density * widths).sum() == pytest.approx(1.0, rel=1e-9)
    # the local slope in log-log between bins far from n = 1 (where binning averages most)
    mid = np.sqrt(edges[:-1] * (edges[1:] - 1.0))
    slope = np.polyfit(np.log(mid[8:-2]), np.log(density[8:-2]), 1)[0]
    assert slope == pytest.approx(1 - 2.5, abs=0.05)


def test_dip_is_one_without_a_hump_and_the_ratio_with_one():
    edges = cmp.log_bins(800)
    falling = cmp.size_density(power_law_counts(2.0, 800), edges)
    assert cmp.dip(falling, edges, 50) == pytest.approx(1.0)
    humped = power_law_counts(2.0, 800)
    humped[300] += humped.sum() // 10
    d = cmp.size_density(humped, edges)
    peak = np.flatnonzero((edges[:-1] <= 300) & (edges[1:] > 300))[0]
    low = d[(edges[:-1] >= 2) & (np.arange(len(d)) <= peak)].min()
    assert cmp.dip(d, edges, 50) == pytest.approx(d[peak] / low) and cmp.dip(d, edges, 50) > 10


def test_recurrence_numbers_of_poisson_and_periodic_times():
    rng = np.random.default_rng(5)
    cv, sharp = cmp.recurrence_numbers(rng.exponential(7.0, 400_000))
    assert cv == pytest.approx(1.0, abs=0.01)
    # the first (half) bin's count has a relative standard error of about 1 / sqrt(400000 * 0.017)
    assert sharp == pytest.approx(cmp.POISSON_SHARPNESS, rel=0.05)
    cv, sharp = cmp.recurrence_numbers(500.0 + rng.uniform(-1.0, 1.0, 10_000))
    assert cv < 0.01 and sharp == pytest.approx(1 / cmp.SHARPNESS_BIN, rel=1e-9)
    assert all(math.isnan(x) for x in cmp.recurrence_numbers(np.array([3.0])))


# -- the command on small runs of both laws ----------------------------------------------------

@pytest.fixture(scope="module")
def two_laws(tmp_path_factory):
    """A Carlson-Langer run (N = 50, 2 seeds x 3000 events) and an aging run (N = 50, 2 x 300, the law's
    own method)."""
    d = tmp_path_factory.mktemp("compare")
    cl = write_cl_config(d / "cl.toml")
    aging = write_config(d / "aging.toml", model={"N": 50, "b": 20.0},
                         run={"events": 300, "transient": 50, "seeds": 2})
    for cfg in (cl, aging):
        res = run_cli("run", cfg, "-o", cfg.with_suffix(".h5"))
        assert res.returncode == 0, res.stderr
    return d, [cl.with_suffix(".h5"), aging.with_suffix(".h5")]


def analysis_process(*args):
    """`python -m analysis ARGS` in a process of its own."""
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 300, env=child_env())


def brute_force(events, n_large, window):
    """(events, large fraction, recurrence times) of one task, from the definitions."""
    n = events["n_slipped"]
    large = np.flatnonzero(n >= n_large)
    T = []
    for a, i in enumerate(large):
        later = [j for j in large[a + 1:] if abs(int(events["epicenter"][j]) - int(events["epicenter"][i])) <= window]
        if later:
            T.append(events["t"][later[0]] - events["t"][i])
    return len(n), (n >= n_large).mean(), np.array(T)


def test_compare_numbers_are_the_catalogs(two_laws, tmp_path):
    """The table's counts, large fractions, recurrence numbers and CV are what the events give."""
    d, paths = two_laws
    out = tmp_path / "cmp"
    res = analysis_here("compare", *paths, "-o", out, "--n-large", "5", "--window", "3", "--bootstrap", "50")
    assert res.returncode == 0, res.stderr
    numbers = json.loads((out / "comparison.json").read_text())
    assert [p["law"] for p in numbers["points"]] == ["carlson-langer", "aging"]
    assert numbers["points"][0]["label"] == "carlson-langer: alpha = 2.5, sigma = 0.01"
    for path, point in zip(paths, numbers["points"]):
        events, tasks, _ = reader.read(path)
        parts = [brute_force({k: v[events["task"] == k_] for k, v in events.items()}, 5, 3)
                 for k_ in range(len(tasks["point"]))]
        T = np.concatenate([p[2] for p in parts]) * float(tasks["nu"][0])
        n_events = sum(p[0] for p in parts)
        assert point["n_events"][0] == n_events
        assert point["fraction_large"][0] == pytest.approx(sum(p[0] * p[1] for p in parts) / n_events, rel=1e-12)
        assert point["n_recurrences"][0] == len(T) > 10
        assert point["cv"][0] == pytest.approx(T.std(ddof=1) / T.mean(), rel=1e-9)
        lo, hi = point["fraction_large"][1:]
        assert lo <= point["fraction_large"][0] <= hi
        assert point["method"] == "blocks" and point["units"] == 40
    table = (out / "comparison.md").read_text()
    assert table.count("\n| carlson-langer") == 1 and table.count("\n| aging") == 1
    for name in ("size.png", "magnitude.png", "recurrence.png"):
        assert (out / name).stat().st_size > 10_000


def test_compare_refuses_to_overwrite_and_bad_options(two_laws, tmp_path):
    d, paths = two_laws
    out = tmp_path / "cmp"
    assert analysis_here("compare", paths[0], "-o", out, "--bootstrap", "5", "--n-large", "5").returncode == 0
    before = (out / "comparison.md").read_text()
    res = analysis_process("compare", paths[1], "-o", out, "--bootstrap", "5", "--n-large", "5")
    assert res.returncode == 2 and res.stderr.strip().count("\n") == 0   # a usage error, as in `ensemble run`
    assert "comparison.md: comparison file exists (use --force" in res.stderr
    assert (out / "comparison.md").read_text() == before
    res = analysis_here("compare", paths[0], "-o", tmp_path / "x", "--n-large", "80")
    assert res.returncode == 2 and "--n-large 80 exceeds the chain of 50 blocks" in res.stderr
    res = analysis_here("compare", paths[0], "-o", tmp_path / "y", "--n-min", "4", "--n-large", "5")
    assert res.returncode == 2 and "--n-min" in res.stderr
    res = analysis_here("compare", d / "missing.h5", "-o", tmp_path / "z")
    assert res.returncode == 1 and "missing.h5" in res.stderr


def test_docs_show_the_committed_comparison():
    """docs/laws/comparison.md is what its comparison.json gives, and docs/laws.md shows its table
    unchanged (a number edited by hand anywhere fails here); the README points to it."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    md = (root / "docs/laws/comparison.md").read_text()
    saved = json.loads((root / "docs/laws/comparison.json").read_text())
    opt = options.make("compare", **saved["options"])
    points = [{"label": p["label"], **{key: np.array([p[name][j] for name in cmp.NUMBERS])
                                       for j, key in enumerate(("numbers", "numbers_lo", "numbers_hi"))}}
              for p in saved["points"]]
    command = md.splitlines()[0].removeprefix("<!-- written by `").removesuffix("` -->")
    assert cmp.table(points, opt, command) == md
    rows = "\n".join(line for line in md[md.index("| point"):].splitlines() if line.startswith("|"))
    assert len(rows.splitlines()) == 2 + len(points) == 8
    assert rows in (root / "docs/laws.md").read_text()
    assert "docs/laws/comparison.md" in (root / "README.md").read_text()


def test_reduce_takes_the_scales_of_the_catalogs_law(two_laws, tmp_path):
    """`analysis reduce` without --mu-bins/--mu-c/--b-cut/--tnu-bins uses the law's scales
    (Law.scales); catalogs of two laws need them given (exit 2 naming them); given, they win."""
    import h5py
    from ensemble.model import laws
    d, (cl, aging) = two_laws
    for path, law in ((cl, "carlson-langer"), (aging, "aging")):
        out = tmp_path / f"{law}.summary.h5"
        res = analysis_here("reduce", path, "-o", out, "--bootstrap", "5")
        assert res.returncode == 0, res.stderr
        scales = laws.get(law).scales
        with h5py.File(out) as h5:
            assert h5.attrs["mu_c"] == scales.mu_c and h5.attrs["b_cut"] == scales.b_cut
            lo, hi, n = scales.mu_bins.split(":")
            np.testing.assert_array_equal(h5["bins/mu"][...], np.linspace(float(lo), float(hi), int(n) + 1))
    res = analysis_here("reduce", cl, aging, "-o", tmp_path / "both.h5", "--mu-c", "1")
    assert res.returncode == 2 and res.stderr.count("\n") == 1
    assert "several friction laws (aging, carlson-langer)" in res.stderr
    assert "give --mu-bins, --tnu-bins, --b-cut" in res.stderr and not (tmp_path / "both.h5").exists()
    res = analysis_here("reduce", cl, aging, "-o", tmp_path / "both.h5", "--mu-c", "1", "--mu-bins=-3:7:100",
                   "--b-cut", "0", "--tnu-bins", "0:4:40", "--bootstrap", "5")
    assert res.returncode == 0, res.stderr
    with h5py.File(tmp_path / "both.h5") as h5:
        assert h5.attrs["mu_c"] == 1.0 and len(h5["bins/mu"]) == 101


def test_the_table_says_in_words_what_a_law_without_small_events_lacks():
    """Ruina's slip law at N = 800 makes only system-size events: no dip below them, no small events
    to fit tau to. The table prints inf and n/a with a note saying why, never nan."""
    from types import SimpleNamespace
    nan, inf = math.nan, math.inf
    x = np.array([18, 1.0, inf, nan, nan, 10, 0.39, 6.0])
    lo = np.array([18, 1.0, inf, nan, nan, 10, 0.2, 4.6])
    hi = np.array([18, 1.0, inf, nan, nan, 10, 0.5, 13.0])
    opt = SimpleNamespace(n_large=50, level=0.95, bootstrap=1000)
    text = cmp.table([{"label": "slip", "numbers": x, "numbers_lo": lo, "numbers_hi": hi}], opt, "cmd")
    row = text.splitlines()[5]
    assert row.split(" | ")[3:6] == ["inf", "n/a", "n/a"] and "0.39 [0.2, 0.5]" in row
    assert "nan" not in text and "n/a: no power law fits the sizes below n = 50" in text


def test_two_laws_with_the_same_keys_are_two_points(two_laws, tmp_path):
    """Ruina's slip law has the aging law's keys (a, b, c): a slip run beside an aging run of equal keys
    reduces and compares as two points, each with its own events, labelled by its law (they used to
    pool into one)."""
    import h5py
    d, (_, aging) = two_laws
    slip = write_config(tmp_path / "slip.toml", model={"N": 50, "b": 20.0, "law": "slip"},
                        run={"events": 40, "transient": 10, "seeds": 2}, integrator={"method": "ark4"})
    res = run_cli("run", slip, "-o", tmp_path / "slip.h5")
    assert res.returncode == 0, res.stderr
    kinds = {}
    for name, path in (("aging", aging), ("slip", tmp_path / "slip.h5")):
        events, _, _ = reader.read(path)
        kinds[name] = int(np.count_nonzero(events["kind"] == schema.KIND_EVENT))
    out = tmp_path / "both.summary.h5"
    res = analysis_here("reduce", aging, tmp_path / "slip.h5", "-o", out, "--bootstrap", "5")
    assert res.returncode == 0, res.stderr
    with h5py.File(out) as h5:
        assert [law.decode() for law in h5["points/law"][...]] == ["aging", "slip"]
        assert h5["points/numbers/n_events"][:, 0].tolist() == [kinds["aging"], kinds["slip"]]
    report = analysis_here("report", out)
    assert report.returncode == 0 and "aging: " in report.stdout and "slip: " in report.stdout, report.stdout
    res = analysis_here("compare", aging, tmp_path / "slip.h5", "-o", tmp_path / "cmp", "--bootstrap", "5")
    assert res.returncode == 0, res.stderr
    table = (tmp_path / "cmp" / "comparison.md").read_text()
    assert f"| aging: a = 0, b = 20, c = 1000 | {kinds['aging']} |" in table
    assert f"| slip: a = 0, b = 20, c = 1000 | {kinds['slip']} |" in table


def test_a_size_distribution_that_does_not_fall_has_no_power_law():
    """Sizes rising over n_min..n_large (a law whose few small events are spread towards the large ones)
    put the likelihood's maximum at the end of the exponent's range: no exponent, not 0 or 10."""
    counts = np.zeros(60)
    counts[2:50] = np.arange(2, 50)              # P(n) ~ n: rising
    assert math.isnan(cmp.power_law_tau(counts, 2, 50))
    counts[2:50] = np.arange(2, 50, dtype=float) ** -2.5
    assert cmp.power_law_tau(counts, 2, 50) == pytest.approx(2.5, abs=1e-6)
