"""The analysis of a plane's catalog (model.geometry = "lattice"; docs/design/geometry.md, step 9).

Block i of an N x M plane lies at x = i % N along strike and y = i // N across; the analysis measures the distance
between two blocks in block units, sqrt(dx^2 + dy^2) (analysis/geometry.py). Here: the commands reduce, report,
plot, export and history read a real plane's catalog; its recurrence times (the next large event with its
epicenter within `window` blocks) are those of a plain scan of its events written here, and would not be with the
chain's |i - j|; the scanner on a synthetic plane, its packing bound and its guard; the seismicity's pairs and
exposures on a plane against a count block by block; planes of other shapes and a chain never pool, and a chain's
point is the same beside a plane as alone; the statistics of chains only refuse a plane in one line. A chain's
summary is unchanged dataset for dataset: tests/test_summary_identity.py (the committed reference).

The run: a plane of 8 x 6 blocks at b = 30 (l = 3), l_across 2 and 3: two points that differ in l_across alone
(at 3 its interior blocks, 1 + 2 l^2 + 2 l_across^2 = 37 > b, creep; at 2, 27, none do), two seeds of 300 rows
each, the history of one event per task (about 10 s); and a chain of 8 blocks of the same parameters.
"""
import json
import math
import sys

import numpy as np
import pytest

from analysis import cli, geometry, merge, summary
from analysis.plot import FIGURES, OWNER
from analysis.recurrence import RecurrenceScanner
from analysis.reduce import LAYOUT
from analysis.statistics import refusal, seismicity
from ensemble.store import reader

from .conftest import run_cli, write_config
from .processes import ROOT, child_env, run_bounded

N, M = 8, 6
CHAINS_ONLY = ("rupture_classes", "slow_slip")     # the statistics whose meaning is a chain's


@pytest.fixture(scope="module")
def plane(tmp_path_factory):
    """(folder, the plane's catalog)."""
    d = tmp_path_factory.mktemp("plane_analysis")
    cfg = write_config(d / "plane.toml", model={"geometry": "lattice", "N": N, "M": M, "b": 30.0},
                       sweep={"l_across": [2.0, 3.0]}, run={"seeds": 2, "events": 300, "transient": 40},
                       output={"history": 1})
    res = run_cli("run", cfg, "-o", d / "plane.h5", timeout=600)
    assert res.returncode == 0, res.stderr
    return d, d / "plane.h5"


def analysis(*args):
    """`python -m analysis ARGS` in a subprocess (the command as a user runs it)."""
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 300, cwd=ROOT, env=child_env())


def reduced(catalogs, out, *options):
    res = analysis("reduce", *catalogs, "-o", out, *options)
    assert res.returncode == 0, res.stderr
    return summary.read(out)


def test_reduce_report_plot_export_and_history_read_a_plane(plane, tmp_path, capsys):
    _, catalog = plane
    s = reduced([catalog], tmp_path / "plane.summary.h5")
    # two points: the same N, l, nu and law keys, another l_across
    assert list(s["points/geometry"]) == ["lattice"] * 2 and list(s["points/M"]) == [M] * 2
    assert list(s["points/l_across"]) == [2.0, 3.0] and list(s["points/N"]) == [N] * 2
    assert set(s["tasks/geometry"]) == {b"lattice"}
    creep = s["points/numbers/n_creep"][:, 0]
    assert creep[0] == 0 and creep[1] > 20, creep          # interior blocks creep at l_across = 3 only
    for name in CHAINS_ONLY:       # refused: no numbers, not wrong ones
        st = next(st for st in LAYOUT.statistics if st.name == name)
        for number in st.numbers:
            assert np.isnan(s[f"points/numbers/{number.name}"]).all(), number.name
    assert np.isfinite(s["points/numbers/mean_tnu"][:, 0]).all() and np.isfinite(s["points/numbers/L_c"][:, 0]).all()

    assert cli.main(["report", str(tmp_path / "plane.summary.h5")]) == 0
    report = capsys.readouterr().out.splitlines()
    assert "point 0: aging: lattice: N = 8, l = 3, nu = 1e-08, a = 0, b = 30, c = 1000, M = 6, l_across = 2" in \
        report[3], report[:4]
    for name in CHAINS_ONLY:
        said = [line for line in report if line.strip().startswith(f"{name}:")]
        assert len(said) == 2 and all("not on a lattice (" in line for line in said), said

    for kind in FIGURES:
        out = tmp_path / f"{kind}.png"
        code = cli.main(["plot", "--figure", kind, "-o", str(out), str(tmp_path / "plane.summary.h5")])
        err = capsys.readouterr().err.strip().splitlines()
        if refusal(OWNER[kind], "lattice"):
            assert code == 1 and not out.exists() and len(err) == 1, err
            assert f"{kind}: not on a lattice (" in err[0], err
        else:
            assert code == 0 and out.stat().st_size > 0, err

    assert cli.main(["export", "-o", str(tmp_path / "numbers"), str(tmp_path / "plane.summary.h5")]) == 0
    lines = (tmp_path / "numbers" / "numbers.csv").read_text().splitlines()
    names = next(line for line in lines if line.startswith("point,")).split(",")
    rows = [dict(zip(names, line.split(","))) for line in lines[lines.index(",".join(names)) + 1:]]
    assert [(r["geometry"], r["M"], r["l_across"]) for r in rows] == [("lattice", "6", "2.0"), ("lattice", "6", "3.0")]
    assert cli.main(["export", "-o", str(tmp_path / "events"), str(catalog)]) == 0
    assert (tmp_path / "events" / "events.csv").stat().st_size > 0
    assert cli.main(["history", str(catalog), "-o", str(tmp_path / "history.png")]) == 0
    assert "along" in capsys.readouterr().out and (tmp_path / "history.png").stat().st_size > 0


def plain_recurrences(t, epicenter, mu, boundary, mu_c, window, distance):
    """[(index of a large event, T to the next large event within `window` of its epicenter, interior)], a loop
    over every pair: independent of analysis/recurrence.py's scan."""
    out = []
    for i in range(len(t)):
        if mu[i] < mu_c:
            continue
        for j in range(i + 1, len(t)):
            if mu[j] >= mu_c and distance(int(epicenter[i]), int(epicenter[j])) <= window:
                out.append((i, t[j] - t[i], not boundary[i]))
                break
    return out


def euclidean(a, b):
    return math.hypot(a % N - b % N, a // N - b // N)


def test_the_recurrence_times_of_a_plane_are_a_plain_scan_of_its_events(plane, tmp_path):
    """The summary's recurrences of every task (counts and sums of T nu, all and interior, and the T nu histogram)
    are the plain scan's at window 2 by the Euclidean distance, and not those of the chain's |i - j|."""
    _, catalog = plane
    window = 2
    s = reduced([catalog], tmp_path / "w2.summary.h5", "--window", window)
    events, tasks, _ = reader.read(catalog)
    column = {name: LAYOUT.column("numbers", name) for name in ("n_rec", "sum_tnu", "n_rec_int", "sum_tnu_int")}
    numbers = s["per_task/numbers"].sum(axis=1)     # (tasks, columns): the stretches of each task summed
    edges = s["bins/tnu"]
    mu_c = float(s["attrs"]["mu_c"])
    chain_distance_differs = False
    for k in range(len(tasks["point"])):
        ev = {name: events[name][(events["task"] == k) & (events["kind"] == 0)] for name in
              ("t", "epicenter", "mu", "boundary")}
        nu = float(tasks["nu"][k])
        found = plain_recurrences(ev["t"], ev["epicenter"], ev["mu"], ev["boundary"], mu_c, window, euclidean)
        T = np.array([f[1] for f in found]) * nu
        interior = np.array([f[2] for f in found], dtype=bool)
        assert len(found) > 50, len(found)
        assert numbers[k, column["n_rec"]] == len(found)
        assert numbers[k, column["sum_tnu"]] == pytest.approx(T.sum(), rel=1e-12)
        assert numbers[k, column["n_rec_int"]] == interior.sum()
        assert numbers[k, column["sum_tnu_int"]] == pytest.approx(T[interior].sum(), rel=1e-12, abs=1e-300)
        idx = np.searchsorted(edges, T, side="right") - 1
        inside = (idx >= 0) & (idx < len(edges) - 1)
        np.testing.assert_array_equal(s["per_task/tnu"][k].sum(axis=0), np.bincount(idx[inside],
                                                                                     minlength=len(edges) - 1))
        along = plain_recurrences(ev["t"], ev["epicenter"], ev["mu"], ev["boundary"], mu_c, window,
                                  lambda a, b: abs(a - b))
        chain_distance_differs |= [f[:2] for f in along] != [f[:2] for f in found]
    assert chain_distance_differs, "the catalog does not tell the plane's distance from the chain's"


@pytest.mark.parametrize("window", [0, 1, 3, 5])
def test_the_scanner_on_a_plane_is_a_plain_scan_whatever_the_chunks(window):
    rng = np.random.default_rng(7)
    n, nx, ny = 2000, 20, 15
    t = np.cumsum(rng.exponential(1.0, n))
    epicenter = rng.integers(0, nx * ny, n)
    mu = rng.uniform(0, 6, n)
    boundary = rng.random(n) < 0.3

    def distance(a, b):
        return math.hypot(a % nx - b % nx, a // nx - b // nx)
    expected = plain_recurrences(t, epicenter, mu, boundary, 3.0, window, distance)
    for chunk in (1, 7, n):
        scanner = RecurrenceScanner(geometry.Shape("lattice", nx, ny), 3.0, window)
        got = []
        for lo in range(0, n, chunk):
            part = slice(lo, lo + chunk)
            src, T, interior = scanner.feed(t[part], epicenter[part], mu[part], boundary[part])
            got += zip(src.tolist(), T.tolist(), interior.tolist())
        got.sort()
        assert [g[0] for g in got] == [e[0] for e in expected]
        np.testing.assert_allclose([g[1] for g in got], [e[1] for e in expected], rtol=1e-12)
        assert [g[2] for g in got] == [e[2] for e in expected]


@pytest.mark.parametrize("nx, ny, window", [(8, 6, 0), (8, 6, 1), (8, 6, 2), (20, 15, 3), (7, 1, 2), (30, 30, 7)])
def test_the_packing_bound_holds_a_packing_and_the_scanner_stops_past_it(nx, ny, window):
    """Blocks on a grid of spacing window + 1 are pairwise more than `window` apart: all pending at once, never more
    than Shape.pending; with buffers one short of them the scan stops with an error rather than write past them."""
    shape = geometry.Shape("lattice", nx, ny)
    grid = [x + nx * y for y in range(0, ny, window + 1) for x in range(0, nx, window + 1)]
    assert shape.pending(window) >= len(grid)
    t = np.arange(len(grid), dtype=float)
    big, no = np.full(len(grid), 5.0), np.zeros(len(grid), dtype=bool)
    scanner = RecurrenceScanner(shape, 4.0, window)
    src, _, _ = scanner.feed(t, np.array(grid), big, no)
    assert len(src) == 0 and scanner.n == len(grid)
    short = RecurrenceScanner(shape, 4.0, window)
    for name in ("t", "x", "y", "interior", "src"):
        setattr(short, name, getattr(short, name)[:len(grid) - 1].copy())
    with pytest.raises(RuntimeError, match="large events pending at once"):
        short.feed(t, np.array(grid), big, no)
    with pytest.raises(ValueError, match="outside the"):
        RecurrenceScanner(shape, 4.0, window).feed(t[:1], np.array([nx * ny]), big[:1], no[:1])


def test_the_seismicity_of_a_plane_counts_euclidean_distances_block_by_block():
    """expose_plane: a mainshock's blocks per distance bin, counted here one by one over the plane (the bins
    half-open, edges not on integers); count_pairs_plane: every pair's bin by its own distance."""
    nx, ny = 9, 7
    distance_edges = np.array([0.0, 1.5, 2.0, 3.2, 5.0])
    time_edges = np.array([-2.0, 0.0, 2.0])
    for x, y in ((2, 5), (0, 0), (4, 3)):
        out = np.zeros((1, 2 * 4))
        seismicity.expose_plane(np.zeros(1), np.array([x]), np.array([y]), np.zeros(1, np.int64), -10.0, 10.0, nx, ny,
                                time_edges, distance_edges, out)
        d = np.array([math.hypot(i - x, j - y) for i in range(nx) for j in range(ny)])
        want = np.histogram(d[d < distance_edges[-1]], distance_edges)[0]    # (half-open bins, as the map's)
        np.testing.assert_array_equal(out.reshape(2, 4), 2.0 * np.stack([want, want]))
    rng = np.random.default_rng(3)
    n = 300
    T = np.sort(rng.uniform(0, 50, n))
    epi = rng.integers(0, nx * ny, n)
    main = rng.random(n) < 0.2
    out = np.zeros((1, 2 * 4), dtype=np.int64)
    seismicity.count_pairs_plane(T, epi % nx, epi // nx, main, np.zeros(n, np.int64), 0, time_edges, distance_edges,
                                 out)
    want = np.zeros((2, 4), dtype=np.int64)
    for m in np.flatnonzero(main):
        for i in range(n):
            dt, d = T[i] - T[m], math.hypot(epi[i] % nx - epi[m] % nx, epi[i] // nx - epi[m] // nx)
            if i != m and -2.0 <= dt < 2.0 and d < distance_edges[-1]:
                want[int(dt >= 0.0), np.searchsorted(distance_edges, d, side="right") - 1] += 1
    np.testing.assert_array_equal(out.reshape(2, 4), want)


def test_planes_of_another_shape_and_a_chain_never_pool(plane, tmp_path):
    """The plane's two points differ in l_across alone; a chain of its N, l, nu and law keys is a third point, and
    that point's numbers are the chain's reduced alone (whose summary holds no geometry at all)."""
    d, catalog = plane
    cfg = write_config(tmp_path / "chain.toml", model={"N": N, "b": 30.0}, run={"seeds": 2, "events": 300,
                                                                              "transient": 40})
    res = run_cli("run", cfg, "-o", tmp_path / "chain.h5", timeout=600)
    assert res.returncode == 0, res.stderr
    alone = reduced([tmp_path / "chain.h5"], tmp_path / "chain.summary.h5")
    both = reduced([tmp_path / "chain.h5", catalog], tmp_path / "both.summary.h5")
    assert not any(name.endswith(("/geometry", "/M", "/l_across")) for name in alone), "a chain's summary changed"
    assert list(both["points/geometry"]) == ["chain", "lattice", "lattice"]
    assert list(both["points/M"]) == [1, M, M] and np.array_equal(both["points/l_across"], [np.nan, 2.0, 3.0],
                                                                  equal_nan=True)
    assert np.bincount(both["tasks/point"]).tolist() == [2, 2, 2]
    for name in alone:
        if name.startswith("points/numbers/") or name.endswith("_density"):
            np.testing.assert_array_equal(both[name][:1], alone[name], err_msg=name)


def test_a_geometry_the_analysis_does_not_know_is_refused_in_one_line():
    with pytest.raises(merge.MergeError) as err:
        merge._known_geometry("ring.h5", {"geometry": np.array(["chain", "ring"])})
    assert "\n" not in str(err.value) and "model.geometry = 'ring'" in str(err.value) and "ring.h5" in str(err.value)
    assert refusal(next(st for st in LAYOUT.statistics if st.name == "slow_slip"), "chain") == ""


def test_the_plane_study_pools_the_seeds_of_each_point(plane, tmp_path):
    """`python -m examples.plane.study` on the plane's catalog (two values of l_across, two seeds each): a point per
    l_across, each the inertial events of its two tasks, its creep episodes counted apart."""
    from examples.plane import study
    _, catalog = plane
    study.main([str(catalog), "--histories", str(catalog), "-o", str(tmp_path / "study")])
    record = json.loads((tmp_path / "study.json").read_text())
    results = record["results"]
    events, tasks, _ = reader.read(catalog)
    with reader.Reader(catalog) as cat:
        kept = [len(cat.histories(task)) for task in range(len(tasks["N"]))]
    assert sum(kept) > 0, kept
    assert len(results) == 2
    for l_across in (2.0, 3.0):
        mine = np.isin(events["task"], np.flatnonzero(tasks["l_across"] == l_across))
        name = f"plane {N} x {M}, b = 30" + (", l_across = 2" if l_across == 2.0 else "")
        r = results[name]
        assert r["seeds"] == 2 and r["events"] == np.sum(mine & (events["kind"] == 0)) > 100
        assert r["creep_episodes"] <= np.sum(mine & (events["kind"] != 0))
        # the histories of every task of the point, pooled under the point's name
        seeds = [k for k in np.flatnonzero(tasks["l_across"] == l_across) if kept[k]]
        if seeds:
            rims = record["rims"][name]
            assert (rims["seeds"], rims["histories"]) == (len(seeds), sum(kept[k] for k in seeds))
    assert len(record["rims"]) == sum(1 for v in (2.0, 3.0) if any(kept[k] for k in np.flatnonzero(
        tasks["l_across"] == v)))
