"""The slow-slip statistic (analysis/statistics/slow_slip.py) against brute force: a synthetic task of mainshocks,
small events and creep episodes, some of them made to be a mainshock's precursory creep, its afterslip or a silent
earthquake (and some made to just miss: a block too far, too late, a taken episode without the epicenter), streamed
in chunks of any size, gives the tables that a loop over every episode and every mainshock counts."""
import math

import numpy as np
import pytest

from analysis import options as reduce_options
from analysis import plot, reduce, summary
from analysis.statistics import slow_slip
from ensemble.model.workspace import KIND_CREEP, KIND_EVENT
from ensemble.store import schema

from .conftest import ROOT
from .processes import analysis_here
from .test_figures import covered, crowded, small_text

N_BLOCKS = 60
NU = 1e-2
OPT = dict(mu_bins="0:4:40", tnu_bins="0:2000:80", mu_c=2.0, b_cut=1.0, blocks=4, afterslip_window=0.5)


def synthetic(n_events, seed):
    """A task's rows in the catalog's order (each when it ends): inertial events one after the other, and creep
    episodes, each its start, duration and blocks: afterslip of an event (beginning at its end or a little
    later, next to its zone or two blocks away), precursory creep taken over by the next event (holding its
    epicenter, or not), silent ones (stopped, some as large as a mainshock) and others."""
    rng = np.random.default_rng(seed)
    rows = []
    t = 0.0
    for _ in range(n_events):
        length = int(rng.integers(1, 30))
        first = int(rng.integers(0, N_BLOCKS - length + 1))
        epicenter = first + int(rng.integers(0, length))
        onset = t + rng.uniform(1.0, 50.0)
        duration = rng.uniform(0.01, 0.2)
        mu = rng.uniform(0.5, 4.0)
        kind = rng.random()
        if kind < 0.3:      # precursory creep taken over at the onset: with the epicenter, or beside it
            lo = epicenter - int(rng.integers(0, 3)) + (int(rng.integers(1, 3)) if rng.random() < 0.3 else 0)
            rows.append(_episode(onset - rng.uniform(0.5, 5.0), onset, lo, lo + int(rng.integers(0, 3)),
                                 schema.ENDING_TAKEN_OVER, rng))
        rows.append(dict(kind=KIND_EVENT, t=onset, duration=duration, first=first, last=first + length - 1,
                         epicenter=epicenter, slip=10 ** mu, ending=schema.ENDING_EVENT))
        end = onset + duration
        for _ in range(int(rng.integers(0, 3))):    # afterslip, or near misses in time or in space
            late = 0.0 if rng.random() < 0.5 else rng.uniform(0.0, 0.8) / NU
            lo = int(rng.integers(first - 3, first + length + 2))
            start = end + late
            rows.append(_episode(start, start + rng.uniform(0.1, 40.0), lo, lo + int(rng.integers(0, 2)),
                                 schema.ENDING_STOPPED, rng))
        if rng.random() < 0.2:      # silent or not: a stopped episode anywhere, small or large
            start = end + rng.uniform(0.0, 5.0)
            lo = int(rng.integers(0, N_BLOCKS - 3))
            rows.append(_episode(start, start + rng.uniform(1.0, 30.0), lo, lo + 2, schema.ENDING_STOPPED, rng,
                                 mu=rng.uniform(0.0, 4.0)))
        t = end
    rows = [r for r in rows if 0 <= r["first"] and r["last"] < N_BLOCKS]
    # an episode taken over ends at the onset of the event that took it, and its row follows the event's
    rows.sort(key=lambda r: (r["t"] + r["duration"], 1) if r["kind"] == KIND_CREEP else (r["t"], 0))
    part = {name: np.zeros(len(rows), dtype=dtype) for name, dtype in schema.EVENT_FIELDS.items()}
    for name in ("kind", "t", "duration", "first", "last", "epicenter", "slip", "ending"):
        part[name] = np.array([r[name] for r in rows], dtype=schema.EVENT_FIELDS[name])
    part["mu"] = np.log10(part["slip"])
    part["n_slipped"] = part["last"] - part["first"] + 1
    return part


def _episode(start, end, first, last, ending, rng, mu=None):
    return dict(kind=KIND_CREEP, t=start, duration=end - start, first=first, last=last, epicenter=first,
                slip=10 ** (rng.uniform(-2.0, 1.0) if mu is None else mu), ending=ending)


def chunks(part, size):
    return [{name: col[a:a + size] for name, col in part.items()} for a in range(0, len(part["t"]), size)]


def brute_force(part, opt):
    """The slow-slip table: every episode against every mainshock, one at a time."""
    k = opt.blocks
    events = np.flatnonzero(part["kind"] == KIND_EVENT)
    n = len(events)
    stretch = {int(r): m * k // n for m, r in enumerate(events)}
    want = np.zeros((k, len(slow_slip.COLUMNS)))
    col = {c: j for j, c in enumerate(slow_slip.COLUMNS)}
    mains = [r for r in events if part["mu"][r] >= opt.mu_c]
    for r in mains:
        want[stretch[r], col["n_main"]] += 1
    precursor, after = set(), set()
    for r in np.flatnonzero(part["kind"] == KIND_CREEP):
        start, first, last = part["t"][r], part["first"][r], part["last"][r]
        end = start + part["duration"][r]
        if part["ending"][r] == schema.ENDING_STOPPED and part["mu"][r] >= opt.mu_c:
            # (the stretch of a creep row: reduce._creep_stretches, by the inertial events before it)
            want[min(int(np.sum(events < r)) * k // n, k - 1), col["n_silent"]] += 1
        if part["ending"][r] == schema.ENDING_TAKEN_OVER:
            for m in mains:
                if (abs(part["t"][m] - end) <= 1e-9 and first - 1 <= part["epicenter"][m] <= last + 1
                        and m not in precursor):
                    precursor.add(m)
                    want[stretch[m], col["n_precursor"]] += 1
        ended = [m for m in mains if part["t"][m] + part["duration"][m] <= start + 1e-9]
        if not ended:
            continue
        m = ended[-1]
        if ((start - part["t"][m] - part["duration"][m]) * NU <= opt.afterslip_window
                and first <= part["last"][m] + 1 and part["first"][m] - 1 <= last):
            want[stretch[m], col["sum_afterslip"]] += part["slip"][r]
            if m not in after:
                after.add(m)
                want[stretch[m], col["n_after"]] += 1
                want[stretch[m], col["sum_main_slip_after"]] += part["slip"][m]
    return want


@pytest.mark.parametrize("seed", [1, 2])
def test_the_table_is_the_rows_whatever_the_chunks(seed):
    part = synthetic(300, seed)
    opt = reduce_options.make(**OPT)
    want = brute_force(part, opt)
    col = {c: j for j, c in enumerate(slow_slip.COLUMNS)}
    total = want.sum(axis=0)
    # the catalog holds every kind, and the near misses too
    assert total[col["n_main"]] > 100 and 20 < total[col["n_precursor"]] < 0.4 * total[col["n_main"]]
    assert 20 < total[col["n_after"]] < 0.9 * total[col["n_main"]] and total[col["n_silent"]] > 5
    written = int(np.count_nonzero(part["kind"] == KIND_EVENT))
    for size in (len(part["t"]), 13, 1):
        out = reduce.reduce_task(chunks(part, size), written, NU, N_BLOCKS, opt, len(part["t"]))
        np.testing.assert_allclose(out["slow_slip"], want, rtol=1e-12, atol=0, err_msg=f"chunks of {size}")
    # the numbers: of the summed table
    u = reduce.LAYOUT.sum_of({name: table.sum(axis=0) for name, table in out.items() if name in reduce.LAYOUT.tables})
    n_main, precursor_share, afterslip_share, ratio, n_silent, silent_share = slow_slip.estimate(u, opt)
    assert n_main == total[col["n_main"]] and n_silent == total[col["n_silent"]]
    assert precursor_share == total[col["n_precursor"]] / n_main
    assert afterslip_share == total[col["n_after"]] / n_main
    assert ratio == pytest.approx(total[col["sum_afterslip"]] / total[col["sum_main_slip_after"]], rel=1e-12)
    assert silent_share == n_silent / (n_silent + n_main)


def test_without_creep_episodes_the_shares_are_zero_and_the_ratio_unknown():
    part = synthetic(200, 3)
    events = {name: col[part["kind"] == KIND_EVENT] for name, col in part.items()}
    opt = reduce_options.make(**OPT)
    out = reduce.reduce_task(chunks(events, 50), len(events["t"]), NU, N_BLOCKS, opt, len(events["t"]))
    u = reduce.LAYOUT.sum_of({name: table.sum(axis=0) for name, table in out.items() if name in reduce.LAYOUT.tables})
    n_main, precursor_share, afterslip_share, ratio, n_silent, silent_share = slow_slip.estimate(u, opt)
    assert n_main > 50 and precursor_share == afterslip_share == n_silent == silent_share == 0
    assert math.isnan(ratio)


NUCLEATION = ROOT / "docs/successors/nucleation.summary.h5"     # b x l, N = 400, a = 0


def test_the_map_shows_each_points_numbers_in_its_cell(tmp_path):
    """--figure slow_slip on the committed nucleation sweep (b and l vary): four panels over the b x l grid, each
    cell's label its point's number and interval (and the count under it), nothing covered, no small text; the
    command writes it; with three varying parameters (another summary's N beside it) it is a one-line error."""
    s = summary.read(NUCLEATION)
    fig = plot.figure(s, "slow_slip", names=[NUCLEATION])
    try:
        assert covered(fig) == [] and small_text(fig) == [] and crowded(fig) == []
        panels = [ax for ax in fig.axes if ax.get_title()]
        assert [ax.get_title() for ax in panels] == [label for _, label, _, _ in slow_slip.PANELS]
        ls, bs = sorted(set(s["points/l"])), sorted(set(s["points/b"]))
        for ax, (name, _, under, fmt) in zip(panels, slow_slip.PANELS):
            assert [t.get_text() for t in ax.get_xticklabels()] == [f"{v:g}" for v in ls]
            cells = {(round(t.get_position()[0]), round(t.get_position()[1])): t.get_text() for t in ax.texts}
            assert len(cells) == len(s["points/b"])
            for i in range(len(s["points/b"])):
                est, lo, hi = s[f"points/numbers/{name}"][i]
                text = cells[(ls.index(s["points/l"][i]), bs.index(s["points/b"][i]))]
                assert text.startswith("-" if np.isnan(est) else f"{est:.2g}\n[{lo:.2g}, {hi:.2g}]"), (name, i, text)
                if np.isfinite(s[f"points/numbers/{under}"][i][0]):
                    assert text.endswith(fmt.format(s[f"points/numbers/{under}"][i][0]))
    finally:
        plot.plt.close(fig)
    res = analysis_here("plot", NUCLEATION, "--figure", "slow_slip", "-o", tmp_path / "map.png")
    assert res.returncode == 0 and (tmp_path / "map.png").stat().st_size > 10_000, res.stderr
    res = analysis_here("plot", NUCLEATION, ROOT / "docs/paper/fig1_b.summary.h5", "--figure", "slow_slip",
                        "-o", tmp_path / "none.png")
    assert res.returncode == 1 and len(res.stderr.strip().splitlines()) == 1 and "slow-slip map" in res.stderr
    assert not (tmp_path / "none.png").exists()
