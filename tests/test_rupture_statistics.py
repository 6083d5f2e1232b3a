"""The rupture statistics (analysis/statistics/rupture_length.py, rupture_classes.py) against brute force: a random
synthetic catalog streamed in chunks of any size gives the tables that one loop over its events counts; the
maximum-likelihood L_0 recovers the scale of exponential draws and says NaN where no decay is there; a
hand-built sequence gives its known classes; the committed catalog's summary reports, draws and exports them."""
import math

import numpy as np
import pytest

from analysis import options as reduce_options
from analysis import reduce
from analysis.statistics import rupture_classes, rupture_length, slip_scaling
from ensemble.model.workspace import KIND_CREEP, KIND_EVENT
from ensemble.store import schema

from .processes import analysis_here
from .test_summary_identity import CATALOG, gunzip

N_BLOCKS = 100
OPT = dict(mu_bins="0:4:40", tnu_bins="0:2000:80", mu_c=2.0, b_cut=1.0, lr_bins="0.5:100.5:20", lr_min=10,
           lr_max=80, class_min=5, uni_edge=0.2, window=3, blocks=4)


def options(**changes):
    return reduce_options.make(**{**OPT, **changes})


def synthetic(n, seed):
    """n rows of one task: inertial events of random rupture zones and epicenters inside them (some reaching an
    end, some whole-chain), with creep episodes among them (which no rupture statistic may count)."""
    rng = np.random.default_rng(seed)
    length = np.minimum(rng.geometric(1 / 15, n), N_BLOCKS)
    length[rng.random(n) < 0.05] = N_BLOCKS
    first = (rng.random(n) * (N_BLOCKS - length + 1)).astype(np.int64)
    last = first + length - 1
    part = {name: np.zeros(n, dtype=dtype) for name, dtype in schema.EVENT_FIELDS.items()}
    part.update(t=np.cumsum(rng.random(n)), first=first, last=last, n_slipped=length,
                epicenter=first + (rng.random(n) * length).astype(np.int64),
                boundary=(first == 0) | (last == N_BLOCKS - 1))
    part["slip"] = length * rng.uniform(0.5, 2.0, n)
    part["mu"] = np.log10(part["slip"])
    part["kind"] = np.where(rng.random(n) < 0.1, KIND_CREEP, KIND_EVENT).astype(np.int8)
    # stress drops: NaN for a creep episode and for a few events (as an older catalog's, which the sums leave out)
    part["stress_drop"] = np.where((part["kind"] == KIND_CREEP) | (rng.random(n) < 0.1), np.nan,
                                   rng.uniform(1.0, 30.0, n))
    return part


def chunks(part, size):
    return [{name: col[a:a + size] for name, col in part.items()} for a in range(0, len(part["t"]), size)]


def brute_force(part, opt):
    """{table: (stretches, width)} of the two statistics, one event at a time."""
    ev = {name: col[part["kind"] == KIND_EVENT] for name, col in part.items()}
    n, k = len(ev["t"]), opt.blocks
    edges_lr, edges_mu = opt.lr_edges, opt.mu_edges
    want = {"lr": np.zeros((k, len(edges_lr) - 1), np.int64), "mu_uni": np.zeros((k, len(edges_mu) - 1), np.int64),
            "mu_bi": np.zeros((k, len(edges_mu) - 1), np.int64), "fit": np.zeros((k, 3)),
            "classes": np.zeros((k, len(rupture_classes.COLUMNS))),
            "slip_lr": np.zeros((k, len(edges_lr) - 1)), "slip": np.zeros((k, 4)),
            "drop_n": np.zeros((k, len(edges_lr) - 1), np.int64), "drop_lr": np.zeros((k, len(edges_lr) - 1)),
            "drop": np.zeros((k, 4))}
    col = {c: j for j, c in enumerate(rupture_classes.COLUMNS)}
    previous = None
    top = min(opt.lr_max, N_BLOCKS - 1)
    for m in range(n):
        s = m * k // n
        length, f, last, e = (int(ev[c][m]) for c in ("n_slipped", "first", "last", "epicenter"))
        mu = ev["mu"][m]
        mean_slip, drop = ev["slip"][m] / length, ev["stress_drop"][m]
        for j in range(len(edges_lr) - 1):
            if edges_lr[j] <= length < edges_lr[j + 1]:
                want["lr"][s, j] += 1
                want["slip_lr"][s, j] += mean_slip
                if not math.isnan(drop):
                    want["drop_n"][s, j] += 1
                    want["drop_lr"][s, j] += drop
        if opt.lr_min <= length <= top:
            want["fit"][s] += (1, length - opt.lr_min, top - opt.lr_min)
            half = 2 if length >= (opt.lr_min + top) / 2 else 0
            want["slip"][s, half:half + 2] += (1, mean_slip)
            if not math.isnan(drop):
                want["drop"][s, half:half + 2] += (1, drop)
        if length >= opt.class_min and f > 0 and last < N_BLOCKS - 1:
            kind = "uni" if min(e - f, last - e) <= opt.uni_edge * (last - f) else "bi"
            want["classes"][s, col["n_classified"]] += 1
            want["classes"][s, col[f"n_{kind}"]] += 1
            for j in range(len(edges_mu) - 1):
                if edges_mu[j] <= mu < edges_mu[j + 1]:
                    want[f"mu_{kind}"][s, j] += 1
            if previous is not None:
                want["classes"][s, col[f"n_{kind}_prev"]] += 1
                if min(abs(e - previous[0]), abs(e - previous[1])) <= opt.window:
                    want["classes"][s, col[f"n_{kind}_rim"]] += 1
        if mu >= opt.mu_c:
            previous = (f, last)
    return want


@pytest.mark.parametrize("seed,lr_max", [(1, 80), (2, 10 ** 9)])
def test_the_tables_are_the_events_whatever_the_chunks(seed, lr_max):
    """lr_max 10^9: the fit ends at N - 1, whole-chain ruptures out."""
    part, opt = synthetic(700, seed), options(lr_max=lr_max)
    want = brute_force(part, opt)
    written = int(np.count_nonzero(part["kind"] == KIND_EVENT))
    for size in (700, 13, 1):
        out = reduce.reduce_task(chunks(part, size), written, 1.0, N_BLOCKS, opt, len(part["t"]))
        for table, name in (("lr", "lr"), ("mu_uni", "mu_uni"), ("mu_bi", "mu_bi"), ("fit", "rupture_length"),
                            ("classes", "rupture_classes"), ("drop_n", "drop_n")):
            np.testing.assert_array_equal(out[name], want[table], err_msg=f"{name}, chunks of {size}")
        for table, name in (("slip_lr", "slip_lr"), ("slip", "slip_scaling"), ("drop_lr", "drop_lr"),
                            ("drop", "stress_drop")):     # sums in another order
            np.testing.assert_allclose(out[name], want[table], rtol=1e-12, atol=0, err_msg=f"{name}, chunks of {size}")
    # the numbers: of the summed tables, as the brute force's sums give them
    n, excess, span = want["fit"].sum(axis=0)
    u = reduce.LAYOUT.sum_of({name: table.sum(axis=0) for name, table in out.items() if name in reduce.LAYOUT.tables})
    l0, n_fit = rupture_length.estimate(u, opt)
    assert n_fit == n and l0 == rupture_length.correlation_length(n, excess, min(lr_max, N_BLOCKS - 1) - opt.lr_min)
    assert np.isfinite(l0)
    n_lo, s_lo, n_hi, s_hi = want["slip"].sum(axis=0)
    d_lo, t_lo, d_hi, t_hi = want["drop"].sum(axis=0)
    np.testing.assert_allclose(slip_scaling.estimate(u, opt),
                               [(s_lo + s_hi) / (n_lo + n_hi), (s_hi / n_hi) / (s_lo / n_lo),
                                (t_lo + t_hi) / (d_lo + d_hi), (t_hi / d_hi) / (t_lo / d_lo)], rtol=1e-12)
    assert n_lo > 0 and n_hi > 0 and 0 < d_lo < n_lo and 0 < d_hi < n_hi
    c = dict(zip(rupture_classes.COLUMNS, want["classes"].sum(axis=0)))
    assert rupture_classes.estimate(u, opt) == [c["n_classified"], c["n_uni"] / c["n_classified"],
                                                c["n_uni_rim"] / c["n_uni_prev"], c["n_bi_rim"] / c["n_bi_prev"]]
    # what the comparison stands on: each class, with and without a predecessor at its rim, in several stretches
    assert np.all(want["classes"].sum(axis=0) > 0) and np.all(want["fit"][:, 0] > 0)


def draws(scale, lo, top, n, rng):
    """n integers lo..top of P(L) ~ exp(-L / scale)."""
    lengths = np.arange(lo, top + 1)
    p = np.exp(-(lengths - lo) / scale)
    return rng.choice(lengths, size=n, p=p / p.sum())


@pytest.mark.parametrize("scale", [5.0, 40.0, 300.0])
def test_the_correlation_length_recovers_the_scale_of_exponential_draws(scale):
    rng = np.random.default_rng(int(scale))
    lo, top, n = 50, 799, 20000
    got = [rupture_length.correlation_length(n, (x - lo).sum(), top - lo) for x in
           (draws(scale, lo, top, n, rng) for _ in range(20))]
    # unbiased to 2 %, each sample within 5 % (an untruncated law's standard error: 1 / sqrt(n) = 0.7 %)
    assert abs(np.mean(got) / scale - 1) < 0.02 and np.std(got) / scale < 0.05


def test_no_decay_and_too_few_events_give_nan():
    fl = rupture_length.correlation_length
    assert math.isnan(fl(1000, 1000 * 50.0, 100))      # mean excess K / 2: a flat law
    assert math.isnan(fl(1000, 1000 * 70.0, 100))      # rising
    assert math.isnan(fl(1, 3.0, 100)) and math.isnan(fl(0, 0.0, 100)) and math.isnan(fl(10, 0.0, 100))
    assert math.isnan(fl(10, 3.0, 0))


def test_a_hand_built_sequence_gives_its_classes():
    # N = 100; window 3, uni_edge 0.2, class_min 5, mu_c 2
    rows = [  # first, last, epicenter, mu: what it is
        (10, 40, 11, 2.5),     # unilateral (1 block from its end), no large event before; large
        (30, 60, 45, 1.0),     # bilateral, epicenter 5 from 40: not at the rim
        (38, 70, 41, 1.0),     # unilateral (3 from 38), epicenter 1 from the rim 40: at the rim
        (0, 20, 10, 3.0),      # reaches block 0: not classified, though at the rim 10; large: the next one's
                               # predecessor
        (15, 30, 22, 1.0),     # bilateral, 2 from 20: at the rim
        (50, 52, 50, 1.0),     # 3 blocks: not classified
    ]
    first, last, epicenter, mu = (np.array(c) for c in zip(*rows))
    ev = {"first": first, "last": last, "epicenter": epicenter, "mu": mu, "n_slipped": last - first + 1}
    classified, uni, has_previous, at_rim, previous = rupture_classes.classes(ev, options(), N_BLOCKS, (-1, -1))
    assert classified.tolist() == [True, True, True, False, True, False]
    assert uni[classified].tolist() == [True, False, True, False]
    assert has_previous.tolist() == [False, True, True, True, True, True]
    assert at_rim.tolist() == [False, False, True, True, True, False]
    assert previous == (0, 20)


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    d = tmp_path_factory.mktemp("ruptures")
    cat = gunzip(CATALOG, d / "catalog.h5")
    out = d / "cat.summary.h5"
    res = analysis_here("reduce", cat, "-o", out, "--lr-min", "1", "--lr-max", "40", "--class-min", "5",
                        "--bootstrap", "200")
    assert res.returncode == 0, res.stderr
    return d, out


def test_report_plot_and_export_show_them(reduced, tmp_path):
    from analysis import summary
    d, out = reduced
    s = summary.read(out)
    assert np.isfinite(s["points/numbers/L0"][:, 0]).any() and s["points/numbers/n_classified"][:, 0].sum() > 0
    res = analysis_here("report", out)
    assert res.returncode == 0 and "L_0" in res.stdout and "unilateral" in res.stdout, res.stdout + res.stderr
    for figure in ("rupture_length", "rupture_classes"):
        res = analysis_here("plot", out, "--figure", figure, "-o", tmp_path / f"{figure}.png")
        assert res.returncode == 0 and (tmp_path / f"{figure}.png").stat().st_size > 10000, res.stderr
    res = analysis_here("export", out, "-o", tmp_path / "tables")
    assert res.returncode == 0, res.stderr
    numbers = (tmp_path / "tables" / "numbers.csv").read_text()
    assert "L0_lo" in numbers and "fraction_unilateral" in numbers
    curves = (tmp_path / "tables" / "curves.csv").read_text()
    assert "mu_uni" in curves and "mean_slip" in curves and "slip_ratio" in numbers
