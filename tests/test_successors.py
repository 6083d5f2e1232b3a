"""`python -m analysis successors`: the claims of the seed's authors' three later papers beside the numbers of
the committed summaries (docs/successors/claims.md is its output, docs/successors.md's table of the nucleation
sweep its table); each claim reads the summary that holds its numbers and the most of its points, the slow-slip
claims every point; what the summaries cannot give is said in words, never nan; the numbers computed here (each
class's share of large events, the widest zone's dependence on magnitude) give known answers on summaries made to
have them."""
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from analysis import stats, successors, summary

from .processes import run_bounded

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs/successors"


def run_analysis(*args):
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 300, cwd=ROOT)


@pytest.fixture(scope="module")
def committed():
    return {p.name.removesuffix(".summary.h5"): summary.read(p) for p in successors.committed()}


def rows_of(out, heading):
    """{statement: text} of the claims table under the section whose heading starts with `heading`."""
    part = out[out.index(f"## {heading}"):]
    lines = part[part.index("|---|---|\n") + len("|---|---|\n"):].split("\n\n")[0].splitlines()
    return dict(line.strip(" |").split(" | ", 1) for line in lines)


def test_the_committed_summaries_give_the_committed_claims():
    """The command's default is the committed summaries; its output is docs/successors/claims.md, and its table
    of every point of the nucleation sweep is docs/successors.md's."""
    res = run_analysis("successors")
    assert res.returncode == 0, res.stderr
    assert res.stdout == (DOCS / "claims.md").read_text()
    table = res.stdout[res.stdout.index("| b | l | regime |"):].split("\n\n")[0].rstrip("\n")
    assert len(table.splitlines()) == 2 + 15
    assert table in (ROOT / "docs/successors.md").read_text()


def test_claims_read_their_own_summary(committed):
    """Given all, the 2017 claims read the N = 800 and 1600 run, its continuum claim the l sweep at N = 1600, the
    nucleation claims the (b, l) sweep; the slow-slip claims every summary that holds their numbers."""
    summaries = list(committed.values())
    names = list(committed)
    chosen = [names[next(k for k, s in enumerate(summaries) if s is successors.points_for(c, summaries)[0])]
              for paper in successors.PAPERS[:2] for c in paper.claims]
    assert chosen == ["ruptures"] * 5 + ["continuum"] + ["nucleation"] * 5
    pooled = successors.pool(successors.PAPERS[2], summaries, names)
    assert [name for _, _, name in pooled] == [n for n in names if n not in ("ruptures",)]


@pytest.mark.parametrize("name", successors.SUMMARIES)
def test_each_summary_alone_says_what_it_cannot_compute(committed, name):
    s = committed[name]
    out = successors.text([s], [name])
    assert not re.search(r"\bnan\b", out, re.IGNORECASE), out
    for paper in successors.PAPERS:
        rows = list(rows_of(out, paper.reference).values())
        assert len(rows) == len(paper.claims)
        for claim, row in zip(paper.claims, rows):
            if paper.pooled:
                missing = not successors.holds(s, paper.needs)
            else:
                missing = successors.points_for(claim, [s]) is None
            assert row.startswith("not computed: needs points") == missing, row


def test_a_point_of_another_law_or_an_older_summary_is_not_read(committed):
    """The nucleation sweep's points relabelled as the slip law are not the papers' model: no claim reads them; a
    summary without the nucleation numbers (reduced before their statistic) is not read for them either."""
    s = committed["nucleation"]
    slip = summary.Read(s.path, dict(s, **{"points/law": np.array(["slip"] * len(s["points/N"]))}))
    out = successors.text([slip], ["slip-run"])
    for paper in successors.PAPERS:
        assert all(row.startswith("not computed: needs points of the aging law")
                   for row in rows_of(out, paper.reference).values()), paper.reference
    old = summary.Read(s.path, {k: v for k, v in s.items() if k != "points/numbers/L_c"})
    rows = rows_of(successors.text([old], ["old"]), successors.PAPERS[1].reference)
    assert all("in a summary that holds L_sc, t_initial, spread_share, L_c, t_nucleation" in row
               for row in rows.values()), rows


def test_the_regimes_name_a_point_that_breaks_them(committed):
    s = summary.Read(committed["nucleation"].path, dict(committed["nucleation"]))
    rows = rows_of(successors.text([s], ["n"]), successors.PAPERS[1].reference)
    assert rows["the regimes of weak and strong frictional instability"].startswith(
        "the onset zone is one block (L_sc = 1) at 3 of 3 points with b above the block stiffness 1 + 2 l^2 "
        "(strong), a creeping cluster (L_sc > 1) at 12 of 12 below it (weak)")
    i = int(np.flatnonzero((s["points/b"] == 25.0) & (s["points/l"] == 3.0))[0])
    j = int(np.flatnonzero((s["points/b"] == 10.0) & (s["points/l"] == 6.0))[0])
    s["points/numbers/L_sc"] = s["points/numbers/L_sc"].copy()
    s["points/numbers/L_sc"][i, 0], s["points/numbers/L_sc"][j, 0] = 1.5, 1.0
    rows = rows_of(successors.text([s], ["n"]), successors.PAPERS[1].reference)
    assert rows["the regimes of weak and strong frictional instability"] == (
        "the onset zone is one block (L_sc = 1) at 2 of 3 points with b above the block stiffness 1 + 2 l^2 "
        "(strong), a creeping cluster (L_sc > 1) at 11 of 12 below it (weak); not so at b = 25, l = 3; b = 10, l = 6")


def test_slow_slip_counts_are_every_points(committed):
    """The pooled counts, recomputed point by point from the summaries' numbers; a silent earthquake and an
    afterslip put at one point are counted and that point named."""
    summaries = [summary.Read(s.path, dict(s)) for s in committed.values()]
    names = list(committed)
    k = names.index("slow_slip_l12_nu1e-4")
    s = summaries[k]
    for key in ("n_silent", "silent_share", "afterslip_share", "afterslip_ratio"):
        s[f"points/numbers/{key}"] = s[f"points/numbers/{key}"].copy()
    i = int(np.flatnonzero((s["points/a"] == 3.0) & (s["points/b"] == 15.0))[0])
    s["points/numbers/n_silent"][i] = (3, 3, 3)
    s["points/numbers/silent_share"][i] = (0.25, 0.1, 0.4)
    s["points/numbers/afterslip_share"][i] = (0.5, 0.4, 0.6)
    s["points/numbers/afterslip_ratio"][i] = (0.125, 0.1, 0.15)
    rows = rows_of(successors.text(summaries, names), successors.PAPERS[2].reference)
    main = below = below_pre = above = above_pre = after = points = with_main = with_after = 0
    for s_, name in zip(summaries, names):
        if "points/numbers/n_main" not in s_:
            continue
        for p in range(len(s_["points/N"])):
            n, share = s_["points/numbers/n_main"][p][0], s_["points/numbers/precursor_share"][p][0]
            points += 1
            if n == 0:
                continue
            with_main += 1
            main += n
            after += n * s_["points/numbers/afterslip_share"][p][0]
            with_after += s_["points/numbers/afterslip_share"][p][0] > 0
            stiff = 1 + 2 * s_["points/l"][p] ** 2
            if s_["points/b"][p] < stiff:
                below, below_pre = below + n, below_pre + n * share
            elif s_["points/b"][p] > stiff:
                above, above_pre = above + n, above_pre + n * share
    assert rows["main shocks"].startswith(f"mainshocks (inertial, mu >= mu_c) at {with_main} of {points} points, "
                                          f"{main:.0f} in all")
    assert f"b below the block stiffness 1 + 2 l^2: {below_pre:.0f} of {below:.0f} mainshocks" in \
        rows["precursory nucleation"]
    assert f"b above it: {above_pre:.0f} of {above:.0f} mainshocks" in rows["precursory nucleation"]
    n_main = s["points/numbers/n_main"][i][0]
    assert rows["afterslip"].startswith(f"afterslip after {after:.0f} of {main:.0f} mainshocks, at {with_after} of "
                                      f"{with_main}")
    assert (f"0.5 [0.4, 0.6] of {n_main:.0f}, its slip 0.125 of theirs (N = 100, l = 12, nu = 0.0001, a = 3, b = 15, "
            "slow_slip_l12_nu1e-4)") in rows["afterslip"]
    assert rows["silent earthquakes"] == (
        f"silent earthquakes (creep episodes that stopped by themselves with mu >= mu_c): 3 at {points} points: 3, "
        "share of the large slips 0.25 [0.1, 0.4] (N = 100, l = 12, nu = 0.0001, a = 3, b = 15, slow_slip_l12_nu1e-4)")


def _made(s, i, table, per_bin):
    """A copy of summary s whose per-stretch table `table` at point i's tasks is per_bin(counts of R(mu)) (the same
    in every unit)."""
    s = summary.Read(s.path, dict(s))
    s[f"per_task/{table}"] = s[f"per_task/{table}"].astype(float).copy()
    tasks = np.flatnonzero(s["tasks/point"] == i)
    s[f"per_task/{table}"][tasks] = per_bin
    return s


def test_a_class_share_of_large_events_is_its_counts(committed):
    """Bilateral events put 30 % above mu_c in every stretch: share 0.3 and an interval of nothing but 0.3."""
    s = committed["ruptures"]
    c = stats.centers(s["bins/mu"])
    row = np.where(c >= s["attrs"]["mu_c"], 3.0, 0.0) / np.sum(c >= s["attrs"]["mu_c"]) \
        + np.where(c < s["attrs"]["mu_c"], 7.0, 0.0) / np.sum(c < s["attrs"]["mu_c"])
    made = _made(s, 0, "mu_bi", row)
    est, lo, hi = successors.large_share(made, 0, "mu_bi")
    assert (est, lo, hi) == pytest.approx((0.3, 0.3, 0.3), rel=1e-12)
    # the real one: the share of its events, its interval about it
    est, lo, hi = successors.large_share(s, 0, "mu_bi")
    counts = s["per_task/mu_bi"][s["tasks/point"] == 0].sum(axis=(0, 1))
    assert est == pytest.approx(counts[c >= 4.0].sum() / counts.sum(), rel=1e-12) and lo < est < hi


def test_the_widest_zone_against_magnitude_is_the_halves_ratio(committed):
    """Large events of L_c 20 in the lower half of their magnitudes and 30 in the upper: ratio 1.5; all in one bin:
    said in words."""
    s = committed["nucleation"]
    i = int(np.flatnonzero((s["points/b"] == 20.0) & (s["points/l"] == 3.0))[0])
    c, mu_c = stats.centers(s["bins/mu"]), s["attrs"]["mu_c"]
    n = np.where((c >= 3.0) & (c < 6.0), 10.0, 0.0)         # events from mu = 3 to 6: large from 4, the middle 5
    made = _made(_made(s, i, "nuc_n", n), i, "nuc_len", n * np.where(c < 5.0, 20.0, 30.0))
    assert successors.widest_zone_ratio(made, i) == "1.5 [1.5, 1.5]"
    one = np.where(np.isclose(c, mu_c + 0.05), 10.0, 0.0)
    made = _made(_made(s, i, "nuc_n", one), i, "nuc_len", one * 20.0)
    assert successors.widest_zone_ratio(made, i) == \
        "not computable: its large events lie within mu = 4 to 4.1, no range of sizes"


def test_bad_input_is_one_line_naming_the_file(tmp_path):
    for path, words in ((tmp_path / "missing.summary.h5", "missing.summary.h5"),
                        (ROOT / "examples/small.toml", "small.toml")):
        res = run_analysis("successors", path)
        assert res.returncode == 1 and not res.stdout, res
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], res.stderr
