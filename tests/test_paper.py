"""`python -m analysis paper`: on the committed full-size summaries it prints the README's claims
table, labelled full size; on a reduced Fig. 1 top run (a real catalog, small) the same claims
with intervals, labelled reduced, with a warning on its short transient; a claim its points do not
allow, or a number that cannot be computed, is said in words, never nan."""
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from analysis import paper, summary
from ensemble.config import MEASURED_TRANSIENT_PER_BLOCK

from .conftest import run_cli
from .processes import run_bounded

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs/paper"
PANELS = ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b")   # the order of docs/paper.md


def run_analysis(*args):
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 300, cwd=ROOT)


def readme_claims():
    text = (ROOT / "README.md").read_text()
    start = text.index("| the paper (Ohmura")
    return text[start:text.index("\n\n", start)]


def test_full_size_summaries_give_the_readme_table():
    res = run_analysis("paper", *(DOCS / f"{p}.summary.h5" for p in PANELS))
    assert res.returncode == 0, res.stderr
    claims = readme_claims()
    assert len(claims.splitlines()) == 10           # header, rule, eight claims
    assert claims in res.stdout
    assert "full size, this code (95% intervals)" in claims
    for p in PANELS:
        assert f"{DOCS / p}.summary.h5: full size, 2e5 events per point" in res.stdout
    assert "warning" not in res.stdout and "reduced" not in res.stdout


@pytest.mark.parametrize("name", PANELS + ("all",))
def test_each_summary_alone_says_what_it_cannot_compute(name):
    s = summary.read(DOCS / f"{name}.summary.h5")
    out = paper.text([s], [name])
    assert not re.search(r"\bnan\b", out, re.IGNORECASE), out
    rows = out[out.index("|---|---|"):].splitlines()[1:]
    assert len(rows) == len(paper.CLAIMS)
    for claim, row in zip(paper.CLAIMS, rows):
        found = paper.points_for(claim, [s])
        assert ("not computed: needs points" in row) == (found is None), row
        assert (found is None) or "[" in row, row       # every computed claim with its intervals


def test_a_point_of_another_law_is_not_the_papers_model():
    """fig1_b's points relabelled as the slip law (what a slip-law run at the same keys gives): said to be another
    model, no claim computed from them, and not set against the full size's aging-law numbers (they were: the slip
    law's recurrence peaks beside the paper's ~500, and "inside" verdicts)."""
    aging = summary.read(DOCS / "fig1_b.summary.h5")
    slip = dict(aging, **{"points/law": np.array(["slip"] * len(aging["points/N"]))})
    out = paper.text([slip], ["slip-run"], reference=[(DOCS / "fig1_b.summary.h5", aging)])
    n = len(aging["points/N"])
    assert f"not the paper's model: slip-run: {n} of the slip law of its {n} point(s)" in out, out
    rows = out[out.index("|---|---|"):].splitlines()[1:1 + len(paper.CLAIMS)]
    assert all("not computed: needs points" in row for row in rows), rows
    # a reduced run's point is set against the full size's only where the law is the same too
    assert paper._same_point(aging, 0, aging, 0) and not paper._same_point(slip, 0, aging, 0)
    assert "not the paper's model" not in paper.text([aging], ["fig1_b"])


def test_claims_read_their_own_panel():
    """Given all five, each claim takes the summary with the most values of what it varies."""
    panels = [summary.read(DOCS / f"{p}.summary.h5") for p in PANELS]
    chosen = [PANELS[next(k for k, s in enumerate(panels) if s is paper.points_for(c, panels)[0])]
              for c in paper.CLAIMS]
    assert chosen == ["fig1_b", "fig1_b", "fig1_b", "fig1_a", "fig1_c", "fig2", "fig2", "large_b"]


def test_measured_transient_is_the_benchmarks():
    """MEASURED_TRANSIENT_PER_BLOCK is the longest transient of benchmarks/results/transient.txt."""
    rows = [line.split("|") for line in (ROOT / "benchmarks/results/transient.txt").read_text().splitlines()
            if line.startswith("| N =")]
    assert max(float(r[6]) for r in rows) == MEASURED_TRANSIENT_PER_BLOCK


def test_ratio_over_an_empty_bin_is_said_in_words():
    assert paper.ratio((82.3, 70.6, 105.0, 0.0), "the dip bin") == "82.3 [70.6, 105]"
    assert paper.ratio((346.0, 160.0, np.nan, 0.47), "the dip bin") == \
        "346 [160, unbounded: the dip bin is empty in 47% of the resamples]"
    assert paper.ratio((np.inf, np.nan, np.nan, 1.0), "the dip bin").startswith("unbounded (the dip bin holds no")
    assert paper.with_interval((np.nan, np.nan, np.nan)) == "not computable from these events"


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """Fig. 1 top's reduced config, smaller still: b = 20..50, 2 seeds x 300 events after 100."""
    d = tmp_path_factory.mktemp("paper")
    res = run_cli("run", ROOT / "examples/paper/fig1_b_reduced.toml", "-o", d / "cat.h5",
                  "--set", "run.seeds=2", "--set", "run.events=300", "--set", "run.transient=100")
    assert res.returncode == 0, res.stderr
    res = run_analysis("reduce", d / "cat.h5", "-o", d / "sum.h5", "--bootstrap", "200")
    assert res.returncode == 0, res.stderr
    return d


@pytest.mark.slow     # the reduced run: a real catalog of 4 points (26 s)
def test_reduced_run_is_labelled_and_warned(reduced):
    res = run_analysis("paper", reduced / "sum.h5")
    assert res.returncode == 0, res.stderr
    out = res.stdout
    assert f"{reduced / 'sum.h5'}: reduced, 600 events per point (2 seeds x 300)" in out
    assert "| reduced, this code (95% intervals) |" in out and ": full size" not in out
    assert (f"warning: {reduced / 'cat.h5'}: run.transient = 100 events at N = 800, shorter than the longest "
            "transient measured (1000 events") in out
    assert not re.search(r"\bnan\b", out, re.IGNORECASE), out
    lines = out.splitlines()
    start = lines.index("|---|---|") + 1
    claims = lines[start:start + len(paper.CLAIMS)]
    rows = dict(line.strip(" |").split(" | ", 1) for line in claims)
    assert list(rows) == [claim.statement for claim in paper.CLAIMS]
    # the b = 20..50 claims are computed; 600 events leave bins of R(mu) empty and peaks unresolved,
    # which each number says in words where it has no interval
    for claim in paper.CLAIMS[:3] + paper.CLAIMS[5:7]:
        row = rows[claim.statement]
        assert "not computed" not in row, row
        assert "[" in row or "unbounded (" in row or "no significant peak" in row, row
    ks = rows[paper.CLAIMS[2].statement]
    assert len(re.findall(r"\d \[0\.\d+, 0\.\d+\]", ks)) == 4, ks     # four KS distances with intervals
    for claim in (paper.CLAIMS[3], paper.CLAIMS[4], paper.CLAIMS[7]):
        assert rows[claim.statement].startswith("not computed: needs points with b = "), rows[claim.statement]


@pytest.mark.slow     # the reduced run: a real catalog of 4 points (26 s)
def test_reduced_run_beside_the_full_size(reduced):
    """Every point of the reduced run is in fig1_b's full-size panel: each compared number with
    both intervals, and whether the full size's value is inside this run's interval."""
    s = summary.read(reduced / "sum.h5")
    out = paper.text([s], ["sum.h5"])
    table = out[out.index("| point | number |"):].splitlines()
    rows = [line.strip(" |").split(" | ") for line in table[2:] if line.startswith("| ")]
    assert len(rows) == 4 * len(paper.COMPARED)
    full = summary.read(DOCS / "fig1_b.summary.h5")
    for k, (point, number, this, other, inside) in enumerate(rows):
        i, key = divmod(k, len(paper.COMPARED))
        key = paper.COMPARED[key]
        est, lo, hi = s[f"points/numbers/{key}"][i]
        ref = full[f"points/numbers/{key}"][i][0]       # fig1_b's points are in the same order, b = 20..50
        assert point == f"b = {s['points/b'][i]:g} (sum)" and this == paper.with_interval((est, lo, hi))
        assert other.startswith(f"{ref:.3g} [") and other.endswith("(fig1_b)")
        assert inside == ("yes" if lo <= ref <= hi else "no")
    assert out.rstrip().splitlines()[-1].startswith(f"{[r[4] for r in rows].count('yes')} of {len(rows)} inside")
    # the full size's estimate decides, not its interval: an interval holding only the full size's
    # lower end leaves the estimate outside
    ref_est, ref_lo, _ = full["points/numbers/fraction_large"][0]
    s["points/numbers/fraction_large"][0] = (ref_lo, ref_lo, ref_lo)
    row = next(line for line in paper.text([s], ["sum.h5"]).splitlines() if line.startswith("| b = 20 (sum) | frac"))
    assert ref_lo < ref_est and row.endswith("| no |"), row
    # nothing to compare with: no such section; a full-size run: none either
    assert "Against the full size" not in paper.text([s], ["sum.h5"], reference=[])
    assert "Against the full size" not in paper.text([full], ["fig1_b"])


def test_bad_input_is_one_line_naming_the_file(tmp_path):
    for path, words in ((tmp_path / "missing.summary.h5", "missing.summary.h5"),
                        (ROOT / "examples/small.toml", "small.toml")):
        res = run_analysis("paper", path)
        assert res.returncode == 1 and not res.stdout, res
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], res.stderr


def test_shape_intervals_resample_the_summarys_units():
    """The R(mu) shape numbers resample what the summary's intervals resample: the stretches of
    fig1_b's one trajectory per point (the README's 82.3 [70.6, 105]); were its units seeds, the
    one seed would leave no spread at all."""
    s = summary.read(DOCS / "fig1_b.summary.h5")
    i = int(np.flatnonzero(s["points/b"] == 20.0)[0])
    assert paper.with_interval(paper.shape_statistics(s, i)["peak_over_dip"]) == "82.3 [70.6, 105]"
    s["points/method"] = np.array(["seeds"] * len(s["points/method"]))
    est, lo, hi, _ = paper.shape_statistics(s, i)["peak_over_dip"]
    assert lo == est == hi


def test_shapes_in_merged_bins_are_those_of_the_coarser_summary():
    """shape_statistics(merge=k) reads R(mu) as a summary whose bins are k of these each: the same numbers and
    intervals as that summary; bins that do not merge by k are an error."""
    s = summary.read(DOCS / "fig1_b.summary.h5")
    coarse = dict(s)
    coarse["bins/mu"] = s["bins/mu"][::5]
    coarse["per_task/mu"] = s["per_task/mu"].reshape(*s["per_task/mu"].shape[:-1], -1, 5).sum(axis=-1)
    for i in range(len(s["points/b"])):
        merged, direct = paper.shape_statistics(s, i, merge=5), paper.shape_statistics(coarse, i)
        for name in paper.SHAPES:
            assert merged[name] == pytest.approx(direct[name], nan_ok=True), name
    assert paper.shape_statistics(s, 0, merge=5)["dip_r"][0] != paper.shape_statistics(s, 0)["dip_r"][0]
    with pytest.raises(ValueError, match="do not merge by 3"):
        paper.shape_statistics(s, 0, merge=3)


@pytest.mark.slow     # the reduced run: a real catalog of 4 points (26 s)
def test_tables_py_on_a_reduced_run_says_reduced(reduced, tmp_path):
    """The reported case: examples/paper/tables.py on a reduced Fig. 1 top summary printed
    "346 [160, nan]" under a heading saying full size. It is analysis paper's table now."""
    import shutil
    shutil.copy(reduced / "sum.h5", tmp_path / "fig1_b.summary.h5")
    res = run_bounded([sys.executable, ROOT / "examples/paper/tables.py", tmp_path], 300, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert "## The paper's claims in a reduced run" in res.stdout and "at full size" not in res.stdout
    assert not re.search(r"\bnan\b", res.stdout, re.IGNORECASE), res.stdout
    claims = res.stdout[res.stdout.index("| the paper (Ohmura"):res.stdout.index("\n\n## One model")]
    assert claims == paper.claims_table([summary.read(tmp_path / "fig1_b.summary.h5")])
