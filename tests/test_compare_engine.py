"""`analysis compare` is a set of statistics of the one reduction (analysis/reduce.py), not a second one.

On the committed catalog of tests/test_summary_identity.py (inertial events beside creep episodes, two
points of two seeds), from the raw events and the definitions alone:

- the engine's tables of the comparison's set (statistics.of("compare")) are the events': counts per n_slipped
  and per mu bin of every task and stretch, and the recurrence times of the events with n >= n_large of every
  stretch (a sample table);
- every number, interval and curve of `compare` is the estimators' of those brute-force units, bootstrapped
  with the point's generator (merge.bootstrap_rng), as the engine draws them;
- `compare` reads what the engine reduced: events added to the engine's tables move its numbers by what they
  add (a comparison streaming the catalog on its own would not see them).
"""
import numpy as np
import pytest

from analysis import compare, merge, options, reduce, stats
from analysis.statistics.regularity import recurrence_numbers
from analysis.statistics.rupture import dip, log_bins, power_law_ks, power_law_tau, size_density
from ensemble.store import reader, schema

from .test_summary_identity import CATALOG, gunzip

OPT = options.make("compare", n_large=5, window=3, bootstrap=60, blocks=4)


@pytest.fixture(scope="module")
def catalog(tmp_path_factory):
    return gunzip(CATALOG, tmp_path_factory.mktemp("compare_engine") / "catalog.h5")


def brute_units(path, opt):
    """{task: [(counts per n (N + 1), counts per mu bin, T nu of the recurrences) per stretch]} from the events."""
    events, tasks, _ = reader.read(path)
    out = {}
    for k in range(len(tasks["point"])):
        mine = (events["task"] == k) & (events["kind"] == schema.KIND_EVENT)
        ev = {name: column[mine] for name, column in events.items()}
        n_blocks, nu, written = int(tasks["N"][k]), float(tasks["nu"][k]), int(mine.sum())
        stretch = (np.arange(written) * opt.blocks) // written
        large = np.flatnonzero(ev["n_slipped"] >= opt.n_large)
        T = [[] for _ in range(opt.blocks)]
        for a, i in enumerate(large):
            later = [j for j in large[a + 1:] if abs(int(ev["epicenter"][j]) - int(ev["epicenter"][i])) <= opt.window]
            if later:
                T[stretch[i]].append((ev["t"][later[0]] - ev["t"][i]) * nu)
        out[k] = [(np.bincount(ev["n_slipped"][stretch == s], minlength=n_blocks + 1),
                   np.histogram(ev["mu"][stretch == s], OPT.mu_edges)[0], np.array(T[s]))
                  for s in range(opt.blocks)]
    return out


def brute_statistics(sizes, mu, T, opt):
    """(numbers in compare.NUMBERS order, R(log10 n), R(mu)) of pooled counts and recurrence times."""
    edges = log_bins(len(sizes) - 1)
    total = sizes.sum()
    density = size_density(sizes, edges)
    tau = power_law_tau(sizes, opt.n_min, opt.n_large)
    numbers = [total, sizes[opt.n_large:].sum() / total, dip(density, edges, opt.n_large), tau,
               power_law_ks(sizes, opt.n_min, tau), len(T), *recurrence_numbers(T)]
    return np.array(numbers), density, mu / total / np.diff(OPT.mu_edges)


def test_the_engines_tables_of_the_comparison_are_the_events(catalog):
    per_task = reduce.reduce_tasks(str(catalog), [0, 1, 2, 3], OPT, compare.LAYOUT)
    for k, stretches in brute_units(catalog, OPT).items():
        for s, (sizes, mu, T) in enumerate(stretches):
            np.testing.assert_array_equal(per_task[k]["n_slipped"][s], sizes)
            np.testing.assert_array_equal(per_task[k]["mu"][s], mu)
            np.testing.assert_array_equal(np.sort(per_task[k]["T_n"][s]), np.sort(T))
    assert sum(len(T) for st in brute_units(catalog, OPT).values() for _, _, T in st) > 20


def test_compare_is_the_bootstrap_of_the_events(catalog):
    units = brute_units(catalog, OPT)
    points = compare.compare([catalog], OPT)
    inputs = merge.read([catalog])
    assert len(points) == len(inputs.points) == 2
    for point, (params, rows) in zip(points, inputs.points):
        flat = [units[int(inputs.tasks["catalog_task"][g])][s] for g in rows for s in range(OPT.blocks)]
        assert point["method"] == "blocks" and point["units"] == len(flat) == 8

        def of(picks):
            return brute_statistics(sum(flat[i][0] for i in picks), sum(flat[i][1] for i in picks),
                                    np.concatenate([flat[i][2] for i in picks]), OPT)
        est = of(range(len(flat)))
        rng = merge.bootstrap_rng(OPT.seed, params)
        draws = [of(p) for p in rng.integers(0, len(flat), size=(OPT.bootstrap, len(flat)))]
        for j, (name, lo, hi) in enumerate((("numbers", "numbers_lo", "numbers_hi"), ("size_density", "size_lo",
                                            "size_hi"), ("mu_density", "mu_lo", "mu_hi"))):
            want_lo, want_hi = stats.percentile_interval(np.array([d[j] for d in draws]), OPT.level)
            for got, want in ((point[name], est[j]), (point[lo], want_lo), (point[hi], want_hi)):
                np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
        assert 0 < point["numbers"][1] < 1 and point["numbers"][5] > 5


def test_compare_reads_the_engines_tables(catalog, monkeypatch):
    """Ten events slipping the whole chain, and a recurrence time of 1, added to every stretch of the engine's
    tables: compare's events, large share and recurrences follow."""
    plain = compare.compare([catalog], OPT)
    reduce_share = merge.reduce_share

    def more(inputs, rows, opt, layout=reduce.LAYOUT):
        out = reduce_share(inputs, rows, opt, layout)
        for tables in out.values():
            tables["n_slipped"][:, -1] += 10
            tables["T_n"] = [np.append(T, 1.0) for T in tables["T_n"]]
        return out
    monkeypatch.setattr(merge, "reduce_share", more)
    added = compare.compare([catalog], OPT)
    for a, b in zip(plain, added):
        n, large, n_rec = a["numbers"][0], a["numbers"][1] * a["numbers"][0], a["numbers"][5]
        extra = 10 * 2 * OPT.blocks      # two tasks a point
        assert b["numbers"][1] == pytest.approx((large + extra) / (n + extra), rel=1e-12)
        assert b["numbers"][5] == n_rec + 2 * OPT.blocks
