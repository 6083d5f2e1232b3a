"""The slow side of the reduction: creep episodes (/events/kind 1) in `analysis reduce`, `report`,
`plot` and `export`, checked on the data of a real catalog.

The catalog: N = 50, b = 14 (below the block stiffness 1 + 2 l^2 = 19: blocks creep) and b = 20
(nothing creeps), two seeds each. Every number is recomputed here from the catalog's rows with numpy:
the aseismic slip fraction (creep slip over all slip, per task and per point), the share of rows that
are creep episodes and of those taken over by an event, and the creep size and duration densities,
whose integral is the share of episodes inside the bins. A summary of format 2 (the committed paper
summaries, reduced before the creep statistics) still reads, reports and exports, without them.
"""
import sys

import numpy as np
import pytest

from analysis import export, plot, report, summary
from analysis.statistics import creep as creep_statistic
from analysis.statistics import holds
from ensemble.store import reader, schema

from .conftest import ROOT, run_cli, write_config
from .processes import run_bounded
from .test_figures import covered, crowded, small_text

CREEP_NUMBERS = tuple(n.name for n in creep_statistic.STATISTIC.numbers)   # the slow side's
CREEPING, STIFF = 14.0, 20.0        # model.b of the two points: below and above the block stiffness 19
SEEDS, EVENTS = 2, 400
NARROW_MU = "0:0.8:16"               # creep mu bins that leave episodes out on both sides
OLD = ROOT / "docs/paper/fig1_b.summary.h5"     # a committed summary of format 2


def analysis(*args):
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 300)


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """The catalog (b = 14 and 20, two seeds each), its rows and tasks, and two summaries of it: the
    default bins and narrow creep mu bins."""
    d = tmp_path_factory.mktemp("creep_statistics")
    cfg = write_config(d / "cfg.toml", model={"N": 50}, sweep={"b": [CREEPING, STIFF]},
                       run={"seeds": SEEDS, "events": EVENTS, "transient": 20}, integrator={"method": "ark4"})
    res = run_cli("run", cfg, "-o", d / "cat.h5", timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    for name, extra in (("sum", ()), ("narrow", (f"--creep-mu-bins={NARROW_MU}",))):
        res = analysis("reduce", d / "cat.h5", "-o", d / f"{name}.h5", "--bootstrap", "200", *extra)
        assert res.returncode == 0, res.stderr
    events, tasks, _ = reader.read(d / "cat.h5")
    return d, events, tasks


def point_of(s, b):
    return int(np.flatnonzero(s["points/b"] == b)[0])


def test_aseismic_fraction_and_shares_are_the_catalogs(reduced):
    """Per point and per task: creep slip over all slip, creep rows over all rows, episodes taken over
    (ending 2) over episodes, as numpy gives them from the rows; the per-task sums add up to the point."""
    d, ev, tasks = reduced
    s = summary.read(d / "sum.h5")
    creep, inertial = ev["kind"] == schema.KIND_CREEP, ev["kind"] == schema.KIND_EVENT
    assert np.count_nonzero(creep & np.isin(ev["task"], np.flatnonzero(tasks["b"] == CREEPING))) > 100
    for b in (CREEPING, STIFF):
        i, mine = point_of(s, b), np.isin(ev["task"], np.flatnonzero(tasks["b"] == b))
        n_creep, n_events = np.count_nonzero(mine & creep), np.count_nonzero(mine & inertial)
        creep_slip, event_slip = ev["slip"][mine & creep].sum(), ev["slip"][mine & inertial].sum()
        number = {name: s[f"points/numbers/{name}"][i] for name in summary.NUMBER_MEANINGS}
        assert number["n_creep"][0] == n_creep and number["n_events"][0] == n_events
        assert number["aseismic_fraction"][0] == pytest.approx(creep_slip / (creep_slip + event_slip), rel=1e-12)
        assert number["creep_share"][0] == pytest.approx(n_creep / (n_creep + n_events), rel=1e-12)
        if n_creep:
            taken = np.count_nonzero(mine & creep & (ev["ending"] == schema.ENDING_TAKEN_OVER))
            assert number["taken_over_share"][0] == pytest.approx(taken / n_creep, rel=1e-12)
    # per task: the stretches of /per_task/creep sum to the task's rows
    per_task = s["per_task/creep"].sum(axis=1)
    for g in range(len(tasks["b"])):
        k = s["tasks/catalog_task"][g]
        rows = ev["task"] == k
        np.testing.assert_array_equal(per_task[g, :2], [np.count_nonzero(rows & creep), np.count_nonzero(
            rows & creep & (ev["ending"] == schema.ENDING_TAKEN_OVER))])
        np.testing.assert_allclose(per_task[g, 2:], [ev["slip"][rows & creep].sum(), ev["slip"][rows & inertial].sum()],
                                   rtol=1e-12)
    print(f"\naseismic fraction at b = {CREEPING:g}, N = 50:",
          creep_statistic.report(s, point_of(s, CREEPING))[-1].strip())


def test_densities_integrate_to_the_share_of_episodes_in_their_bins(reduced):
    """sum(density * width) over the bins = episodes inside the bins / all episodes, for the size
    (default and narrow bins, half-open [lo, hi)) and the duration in units of 1/nu."""
    d, ev, tasks = reduced
    mine = (ev["kind"] == schema.KIND_CREEP) & np.isin(ev["task"], np.flatnonzero(tasks["b"] == CREEPING))
    nu = tasks["nu"][0]
    values = {"creep_mu": ev["mu"][mine], "creep_duration": np.log10(ev["duration"][mine] * nu)}
    shares = []
    for name in ("sum", "narrow"):
        s = summary.read(d / f"{name}.h5")
        i = point_of(s, CREEPING)
        for curve, x in values.items():
            edges = s[f"bins/{curve}"]
            inside = np.count_nonzero((x >= edges[0]) & (x < edges[-1])) / len(x)
            integral = np.sum(s[f"points/{curve}_density"][i] * np.diff(edges))
            assert integral == pytest.approx(inside, rel=1e-12), (name, curve)
            shares.append(inside)
            # the bands hold the estimate
            est, lo, hi = (s[f"points/{curve}_{part}"][i] for part in ("density", "lo", "hi"))
            assert np.all((lo <= est + 1e-15) & (est <= hi + 1e-15))
    assert shares[:2] == [1.0, 1.0] and 0.3 < shares[2] < 0.95     # narrow bins: some left out
    np.testing.assert_array_equal(summary.read(d / "narrow.h5")["bins/creep_mu"], np.linspace(0, 0.8, 17))


def test_a_point_above_the_block_stiffness_has_no_creep(reduced):
    """b = 20: no creep rows, an aseismic fraction of exactly 0 (its interval too), no densities;
    the report says "none" there and gives every number with its interval at b = 14."""
    d, _, _ = reduced
    s = summary.read(d / "sum.h5")
    i = point_of(s, STIFF)
    np.testing.assert_array_equal(s["points/numbers/n_creep"][i], [0, 0, 0])
    np.testing.assert_array_equal(s["points/numbers/aseismic_fraction"][i], [0, 0, 0])
    assert np.isnan(s["points/numbers/taken_over_share"][i]).all()
    assert np.isnan(s["points/creep_mu_density"][i]).all() and np.isnan(s["points/creep_duration_density"][i]).all()
    assert list(creep_statistic.creeping(s)) == [b == CREEPING for b in s["points/b"]]
    text = report.table(s).split("\npoint ")[1:]
    stiff, creeping = text[i], text[point_of(s, CREEPING)]
    assert "creep episodes  none" in stiff and "aseismic" not in stiff
    for name in CREEP_NUMBERS:
        line = next(line for line in creeping.splitlines() if report.LABELS[name] in line)
        assert "[" in line, line      # with its interval


def test_bootstrap_intervals_contain_the_estimates(reduced):
    d, _, _ = reduced
    s = summary.read(d / "sum.h5")
    i = point_of(s, CREEPING)
    for name in CREEP_NUMBERS:
        est, lo, hi = s[f"points/numbers/{name}"][i]
        assert lo <= est <= hi, name
    est, lo, hi = s["points/numbers/aseismic_fraction"][i]
    assert 0 < lo < est < hi < 1


def test_export_writes_the_creep_columns_and_curves_with_their_meanings(reduced, tmp_path):
    d, _, _ = reduced
    out = tmp_path / "tables"
    res = analysis("export", d / "sum.h5", "-o", out)
    assert res.returncode == 0, res.stderr
    numbers = export.numbers(d / "sum.h5")
    columns = export.columns(d / "sum.h5", "numbers")
    s = summary.read(d / "sum.h5")
    for name in CREEP_NUMBERS:
        for j, suffix in enumerate(("", "_lo", "_hi")):
            np.testing.assert_array_equal(numbers[name + suffix], s[f"points/numbers/{name}"][:, j])
            assert columns[name + suffix][1].startswith(summary.NUMBER_MEANINGS[name][1])
    header = (out / "numbers.csv").read_text().splitlines()
    names = next(line for line in header if not line.startswith("#")).split(",")
    assert {"aseismic_fraction", "aseismic_fraction_lo", "aseismic_fraction_hi", "n_creep", "creep_share",
            "taken_over_share"} <= set(names)
    curves = export.curves(d / "sum.h5")
    i = point_of(s, CREEPING)
    for curve in ("creep_mu", "creep_duration"):
        rows = (curves["curve"] == curve) & (curves["point"] == i)
        np.testing.assert_array_equal(curves["density"][rows], s[f"points/{curve}_density"][i])
        np.testing.assert_array_equal(curves["edge_lo"][rows], s[f"bins/{curve}"][:-1])
    assert "creep_duration: the log10(duration nu) of the creep episodes" in export.columns(d / "sum.h5", "curves")[
        "curve"][1]


def test_creep_figure_shows_the_creeping_points_and_the_fraction(reduced, tmp_path):
    """--figure creep: size and duration densities of the point that creeps (not of the other), the
    aseismic fraction of both against b; nothing covers data, no small text."""
    d, _, _ = reduced
    s = summary.read(d / "sum.h5")
    fig = plot.figure(s, "creep", names=[d / "sum.h5"])
    try:
        assert covered(fig) == [] and small_text(fig) == [] and crowded(fig) == []
        size, duration, fraction = fig.axes
        for ax in (size, duration):
            assert [line.get_label() for line in ax.lines if not line.get_label().startswith("_")] == ["b = 14"]
        x, y = fraction.lines[0].get_data()
        np.testing.assert_array_equal(x, [CREEPING, STIFF])
        assert y[1] == 0 and y[0] == s["points/numbers/aseismic_fraction"][point_of(s, CREEPING), 0]
    finally:
        plot.plt.close(fig)
    res = analysis("plot", d / "sum.h5", "--figure", "creep", "-o", tmp_path / "creep.png")
    assert res.returncode == 0 and (tmp_path / "creep.png").stat().st_size > 0, res.stderr


def test_a_summary_of_format_2_reads_reports_exports_without_creep(tmp_path):
    """The committed paper summaries (format 2, no creep statistics) still read; the report adds
    nothing, the export no creep column, and --figure creep is a one-line error (exit 1)."""
    s = summary.read(OLD)
    assert s["attrs"]["format"] == "bk-summary-2" != summary.FORMAT
    assert not holds(s, creep_statistic.STATISTIC) and not creep_statistic.creeping(s).any()
    assert "creep" not in report.table(s)
    assert not any("creep" in name or "aseismic" in name for name in export.numbers(OLD).dtype.names)
    assert set(export.curves(OLD)["curve"]) == {"mu", "tnu", "tnu_interior"}
    res = analysis("plot", OLD, "--figure", "creep", "-o", tmp_path / "creep.png")
    assert res.returncode == 1 and "no creep episodes" in res.stderr and len(res.stderr.splitlines()) == 1, res.stderr
    assert not (tmp_path / "creep.png").exists()
