"""The seismicity around large events (analysis/statistics/seismicity.py) against the events themselves:
its pairs and exposures by brute force on the committed catalog of tests/test_summary_identity.py, streamed
in chunks of any size; a hand-built chain whose counts and exposures are known; a uniform random catalog
whose windows are often cut by the task's ends, where the rates must be the background's everywhere."""
import sys

import h5py
import numpy as np
import pytest

from analysis import options as reduce_options
from analysis import reduce
from analysis.statistics import seismicity
from ensemble.model.workspace import KIND_EVENT
from ensemble.store import reader, schema

from .processes import ROOT, child_env, run_bounded
from .test_summary_identity import CATALOG, gunzip

# bins narrow enough that the committed catalog (N = 60, inter-event times of a few hundred T nu) fills
# cells on both sides of its mainshocks, near the epicenter and far from it
OPT = dict(seis_time_bins="-2000:2000:16", seis_distance_bins="0:30:10", seis_near=6.0, seis_ring=18.0,
           seis_short=250.0, seis_long=1000.0)


def brute_force(t, epicenter, mu, nu, n_blocks, opt):
    """(pairs, exposure) of one task, (stretches, time bins, distance bins), the O(n^2) way."""
    te, de = opt.seis_time_edges, opt.seis_distance_edges
    nt, nd, k, n = len(te) - 1, len(de) - 1, opt.blocks, len(t)
    pairs, exposure = np.zeros((k, nt, nd), dtype=np.int64), np.zeros((k, nt, nd))
    T = [float(x) * nu for x in t]
    start, end = T[0], T[-1]
    for m in range(n):
        if mu[m] < opt.mu_c:
            continue
        s = m * k // n
        for i in range(n):
            dt, d = T[i] - T[m], abs(int(epicenter[i]) - int(epicenter[m]))
            if i == m or not te[0] <= dt < te[-1] or not de[0] <= d < de[-1]:
                continue
            j = max(q for q in range(nt) if te[q] <= dt)
            c = max(q for q in range(nd) if de[q] <= d)
            pairs[s, j, c] += 1
        for j in range(nt):
            cover = max(0.0, min(T[m] + te[j + 1], end) - max(T[m] + te[j], start))
            for c in range(nd):
                blocks = sum(1 for x in range(n_blocks) if de[c] <= abs(x - int(epicenter[m])) < de[c + 1])
                exposure[s, j, c] += cover * blocks
    return pairs, exposure


def options(**changes):
    return reduce_options.make(**{"mu_bins": "0:7:70", "tnu_bins": "0:2000:80", "mu_c": 4.0, "b_cut": 3.0, **OPT,
                           **changes})


def tables(chunks, written, nu, n_blocks, opt):
    out = reduce.reduce_task(chunks, written, nu, n_blocks, opt)
    shape = (opt.blocks, len(opt.seis_time_edges) - 1, len(opt.seis_distance_edges) - 1)
    return out["seis_pairs"].reshape(shape), out["seis_exposure"].reshape(shape), out


def test_pairs_and_exposures_are_those_of_the_events_whatever_the_chunks(tmp_path):
    cat = gunzip(CATALOG, tmp_path / "catalog.h5")
    opt = options()
    checked = 0
    with reader.Reader(str(cat)) as r:
        for task in range(len(r.tasks["N"])):
            nu, n_blocks = float(r.tasks["nu"][task]), int(r.tasks["N"][task])
            written = r.count(task, KIND_EVENT)
            ev = {name: [] for name in ("t", "epicenter", "mu", "kind")}
            for part in r.task_events(task, 1 << 16):
                for name in ev:
                    ev[name].append(part[name])
            ev = {name: np.concatenate(v) for name, v in ev.items()}
            inertial = ev["kind"] == KIND_EVENT
            want_pairs, want_exposure = brute_force(ev["t"][inertial], ev["epicenter"][inertial],
                                                    ev["mu"][inertial], nu, n_blocks, opt)
            whole = None
            for chunk in (1 << 16, 7, 1):
                pairs, exposure, out = tables(r.task_events(task, chunk), written, nu, n_blocks, opt)
                np.testing.assert_array_equal(pairs, want_pairs, err_msg=f"task {task}, chunks of {chunk}")
                np.testing.assert_allclose(exposure, want_exposure, rtol=1e-12, atol=0)
                if whole is None:
                    whole = out
                for name in ("seis_pairs", "seis_exposure", "seismicity"):    # exactly, whatever the chunks
                    np.testing.assert_array_equal(out[name], whole[name], err_msg=f"{name}, chunks of {chunk}")
            assert whole["seismicity"][:, 0].sum() == np.count_nonzero(ev["mu"][inertial] >= opt.mu_c)
            checked += want_pairs.sum() > 0
    # what the comparison stands on: pairs before and after, near and far, in tasks of both points
    assert checked >= 3


def hand_built(t, epicenter, mu, chunk):
    """The chunks of one task of inertial events (every column a statistic reads)."""
    n = len(t)
    part = {name: np.zeros(n, dtype=dtype) for name, dtype in schema.EVENT_FIELDS.items()}
    part.update(t=np.asarray(t, float), epicenter=np.asarray(epicenter, np.int64), mu=np.asarray(mu, float),
                slip=10.0 ** np.asarray(mu, float), n_slipped=np.ones(n, np.int64))
    part["kind"][:] = KIND_EVENT
    return [{name: col[a:a + chunk] for name, col in part.items()} for a in range(0, n, chunk)]


def test_a_hand_built_chain_gives_its_known_counts_and_exposures():
    # N = 10, nu = 1; one mainshock (mu 5) at t = 2, block 6; the task's span is [0, 10]
    t, epicenter, mu = [0, 1, 2, 3, 10], [5, 5, 6, 2, 5], [0, 0, 5, 0, 0]
    opt = options(seis_time_bins="-4:4:8", seis_distance_bins="0:5:5",
                  seis_near=2.0, seis_ring=5.0, seis_short=2.0, seis_long=4.0, blocks=1)
    for chunk in (5, 2, 1):
        pairs, exposure, out = tables(hand_built(t, epicenter, mu, chunk), 5, 1.0, 10, opt)
        want = np.zeros((8, 5), dtype=np.int64)
        want[2, 1] = want[3, 1] = 1      # t = 0 and 1 at block 5: 2 and 1 before, one block away
        want[5, 4] = 1                   # t = 3 at block 2: 1 after, 4 blocks away (t = 10: beyond the window)
        np.testing.assert_array_equal(pairs[0], want)
        # the window [-4, 4) of t = 2 starts 2 before the task: bins [-4, -2) uncovered; blocks at distance
        # 0, 1, 2, 3, 4 of block 6 in 0..9: 1, 2, 2, 2, 1 (10 is beyond the chain's end)
        cover = np.array([0, 0, 1, 1, 1, 1, 1, 1], float)
        np.testing.assert_array_equal(exposure[0], np.outer(cover, [1, 2, 2, 2, 1]))
        np.testing.assert_array_equal(out["seismicity"][0], [1, 4, 10 * 10.0])   # mainshocks, gaps, N x span
    u = reduce.LAYOUT.sum_of({name: out[name].sum(axis=0) for name in out})
    background, fore, after, quiet, doughnut = seismicity.estimate(u, opt)
    assert background == 4 / 100
    assert fore == 2 / (2 * 3)           # [-2, 0) x distance < 2: 2 events over 2 T nu x (1 + 2) blocks
    assert after == 0 / (2 * 3)
    assert np.isnan(quiet)               # [-4, -2) was never observed
    assert doughnut == np.inf           # no event in the ring [2, 5) just before: a doughnut's opposite


def sites(epicenter, n_blocks, distance_edges):
    """(mainshocks, distance bins): the blocks of the chain in each distance bin [lo, hi) of each epicenter,
    counted one by one."""
    d = np.abs(np.arange(n_blocks)[None, :] - np.asarray(epicenter)[:, None])
    k = np.searchsorted(distance_edges, d, side="right") - 1
    return np.array([[np.count_nonzero(row == j) for j in range(len(distance_edges) - 1)] for row in k], float)


@pytest.mark.parametrize("edges", ["0:40:20", "0:7:3", "-2:9.5:5", "1.5:3.5:4"])
def test_the_exposure_counts_the_blocks_in_each_distance_bin(edges):
    """The exposure kernel's blocks per distance bin (counted from the bin's edges) are the blocks of the chain
    counted one by one, near both ends and in its middle, for integer and fractional edges."""
    distance_edges, n_blocks = reduce.parse_bins(edges), 23
    time_edges = np.array([0.0, 1.0])
    epicenter = np.arange(n_blocks)
    out = np.zeros((n_blocks, len(distance_edges) - 1))
    seismicity.expose(np.zeros(n_blocks), epicenter, epicenter, 0.0, np.inf, n_blocks, time_edges, distance_edges,
                      out)
    np.testing.assert_array_equal(out, sites(epicenter, n_blocks, distance_edges))


def test_cut_windows_leave_the_rates_unbiased():
    """Uniform random events (a Poisson process in time, every block alike) in a task only as long as a
    window: the rate of every cell is the background's, within its noise, although most windows are cut."""
    rng = np.random.default_rng(5)
    n, n_blocks = 20000, 40
    t = np.sort(rng.uniform(0, 2000, n))
    epicenter, mu = rng.integers(0, n_blocks, n), np.where(rng.random(n) < 0.02, 5.0, 0.0)
    opt = options(seis_time_bins="-1000:1000:4", seis_distance_bins="0:40:2", blocks=1)
    pairs, exposure, out = tables(hand_built(t, epicenter, mu, 4096), n, 1.0, n_blocks, opt)
    rate = pairs[0] / exposure[0]
    background = out["seismicity"][0, 1] / out["seismicity"][0, 2]
    # every event pairs with hundreds of mainshocks: the noise is that of the 20000 events, 1 / sqrt(20000) = 0.7%
    assert np.all(np.abs(rate / background - 1) < 0.03), rate / background
    # counted as if every window were whole, the rates would be 3/4 of the background's (a window covers
    # 1500 of its 2000 T nu on average)
    whole = 2000 * sites(epicenter[mu >= opt.mu_c], n_blocks, opt.seis_distance_edges).sum(axis=0)
    assert np.all(pairs[0].sum(axis=0) / whole < 0.8 * background)


def test_report_plot_and_export_show_the_seismicity(tmp_path):
    cat, out = gunzip(CATALOG, tmp_path / "catalog.h5"), tmp_path / "summary.h5"
    edges = [f"--{k.replace('_', '-')}={v}" for k, v in OPT.items()]
    for args in (["reduce", cat, "-o", out, *edges], ["plot", out, "--figure", "seismicity", "-o", tmp_path / "s.png"],
                 ["export", out, "-o", tmp_path / "tables"], ["report", out]):
        res = run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 600, cwd=ROOT, env=child_env())
        assert res.returncode == 0, res.stderr
    for label in ("background rate", "foreshock rate", "aftershock rate", "quiescence ratio", "doughnut ratio"):
        assert label in res.stdout
    assert (tmp_path / "s.png").stat().st_size > 0
    with h5py.File(out, "r") as s:
        rate = s["points/seismicity_rate"][:]
        assert rate.shape == (2, 16, 10) and np.isfinite(rate).any()
        assert s.attrs["seis_near"] == 6.0
    text = (tmp_path / "tables" / "seismicity.csv").read_text()
    rows = [line for line in text.splitlines() if not line.startswith("#")]
    assert rows[0].startswith("point,") and len(rows) == 1 + 2 * 16 * 10


def test_a_resample_sums_only_the_cells_the_numbers_read_and_gives_the_same_intervals(tmp_path):
    """The bootstrap draws only the map's cells that the seismicity's numbers read (Statistic.drawn): every
    number, curve and interval is the same as when every cell is drawn, to the last bit."""
    import dataclasses

    from analysis import merge
    from analysis.statistics import Layout

    cat = gunzip(CATALOG, tmp_path / "catalog.h5")
    opt = options(blocks=5, bootstrap=200)
    inputs = merge.read([str(cat)])
    params, rows = inputs.points[0]
    per_task = reduce.reduce_tasks(str(cat), [int(inputs.tasks["catalog_task"][g]) for g in rows], opt)
    ids = sorted(per_task)
    every = Layout(tuple(dataclasses.replace(s, drawn=None) for s in reduce.LAYOUT.statistics))
    assert reduce.LAYOUT.drawn(opt) and not every.drawn(opt)
    subset = reduce.point_statistics(per_task, ids, opt, merge.bootstrap_rng(0, params))
    whole = reduce.point_statistics(per_task, ids, opt, merge.bootstrap_rng(0, params), layout=every)
    assert np.isfinite(subset["numbers"][:, 1]).any()
    np.testing.assert_array_equal(subset["numbers"], whole["numbers"])
    for a, b in zip(subset["curves"], whole["curves"]):
        np.testing.assert_array_equal(a, b)
