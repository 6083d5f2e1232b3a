"""Adding a statistic touches one file (analysis/statistics/__init__.py says what it declares).

A copy of the analysis package gets one new module, analysis/statistics/one_block.py: the share of the
inertial events that slip at most `small_n` blocks, from an additive table of its own, with its own option
(--small-n), report line, figure (--figure small_share) and export table (small.csv). Nothing else is
edited; the copy's commands on the committed catalog of tests/test_summary_identity.py then take the
option and show the rest, and the summary stores the table, the number and the option, describes them,
and its estimate and interval are those of the events themselves.
"""
import re
import sys

import h5py
import numpy as np

from .processes import child_env, package_copy, run_bounded
from .test_summary_identity import CATALOG, gunzip

ONE_BLOCK = '''"""The share of the inertial events that slip at most `small_n` blocks (a test's new statistic),
with its own option, report line, figure and export table."""
import numpy as np

from . import ExportTable, Figure, Number, Option, Statistic, Table


def feed(acc, rows):
    if rows.ev is not None:
        acc.add("one_block", "n_small", rows.block, rows.ev["n_slipped"] <= rows.opt.small_n)


def estimate(u, opt):
    with np.errstate(invalid="ignore", divide="ignore"):
        return [u.column("one_block", "n_small") / u.column("numbers", "n_events")]


def report(s, i):
    return [f"    small events (n <= {s['attrs']['small_n']}): {s['points/numbers/small_share'][i][0]:.6f}"]


def draw(summaries, fig, keys, labels, names, title):
    ax = fig.add_subplot()
    for s in summaries:
        ax.plot(s["points/numbers/small_share"][:, 0], "o", label="small share")
    ax.set_title(title)


def table(s):
    columns = {"point": ("index", "parameter point"), "small_share": ("1", "share of the small events")}
    return columns, {"point": np.arange(len(s["points/N"])), "small_share": s["points/numbers/small_share"][:, 0]}


STATISTIC = Statistic(
    "one_block", 50,
    tables=(Table("one_block", "count", "events slipping at most small_n blocks", columns=("n_small",)),),
    numbers=(Number("small_share", "1", "share of the inertial events that slip at most small_n blocks"),),
    feed=feed, estimate=estimate, uses_tables=("numbers",), report=report,
    options=(Option("small_n", "count", 1, "blocks", "a small event slips at most this many blocks", 1, 10 ** 9),),
    figures=(Figure("small_share", "the share of small events of every point", lambda n: (4, 3), draw),),
    exports=(ExportTable("small", "one row per point: its share of small events", table),))
'''


def _tree(tmp_path, with_statistic):
    tree = tmp_path / ("tree" if with_statistic else "without")
    package_copy(tree, "analysis", "ensemble")
    if with_statistic:
        (tree / "analysis" / "statistics" / "one_block.py").write_text(ONE_BLOCK)
    return tree


def _analysis(tree, *args):
    return run_bounded([sys.executable, "-m", "analysis", *map(str, args)], 600, cwd=tree,
                       env=child_env(PYTHONPATH=str(tree)))


def test_a_statistic_is_one_file(tmp_path):
    """One new file, nothing else edited: `reduce --small-n` takes its option, the summary stores its table, number
    and option, `report` prints its line, `plot --figure small_share` draws its figure and `export` writes its
    table. Without the file (the same copy, the registry without it) none of these know it."""
    tree = _tree(tmp_path, True)
    cat = gunzip(CATALOG, tmp_path / "catalog.h5")
    out = tmp_path / "summary.h5"
    res = _analysis(tree, "reduce", cat, "-o", out, "--small-n", 2)
    assert res.returncode == 0, res.stderr
    res = _analysis(tree, "report", out)
    assert res.returncode == 0 and "small events (n <= 2): " in res.stdout, res.stdout + res.stderr
    res = _analysis(tree, "plot", out, "--figure", "small_share", "-o", tmp_path / "small.png")
    assert res.returncode == 0 and (tmp_path / "small.png").stat().st_size > 1000, res.stderr
    res = _analysis(tree, "export", out, "-o", tmp_path / "tables")
    assert res.returncode == 0, res.stderr
    csv = tmp_path / "tables" / "small.csv"
    skip = int(re.search(r"skip_header=(\d+)", csv.read_text().splitlines()[0]).group(1))
    exported = np.genfromtxt(csv, delimiter=",", names=True, comments=None, skip_header=skip)
    without = _tree(tmp_path, False)
    for args in (("reduce", cat, "-o", tmp_path / "other.h5", "--small-n", 2),
                 ("plot", out, "--figure", "small_share", "-o", tmp_path / "other.png")):
        res = _analysis(without, *args)
        assert res.returncode == 2 and ("small-n" in res.stderr or "small_share" in res.stderr), res.stderr
    with h5py.File(cat, "r") as c, h5py.File(out, "r") as s:
        events = c["events"]
        inertial = events["kind"][:] == 0
        task, one = events["task"][:][inertial], events["n_slipped"][:][inertial] <= 2
        assert s.attrs["small_n"] == 2
        table = s["per_task/one_block"][:]
        assert table.shape[:2] == s["per_task/mu"].shape[:2] and table.shape[2] == 1
        np.testing.assert_array_equal(table.sum(axis=(1, 2)), np.bincount(task[one], minlength=len(table)))
        share = s["points/numbers/small_share"][:]
        np.testing.assert_array_equal(exported["small_share"], share[:, 0])
        for i in range(len(share)):
            mine = np.isin(task, np.flatnonzero(s["tasks/point"][:] == i))
            assert share[i, 0] == one[mine].mean()
            assert share[i, 1] < share[i, 0] < share[i, 2]      # an interval from the bootstrap around it
        assert "at most small_n blocks" in s["points/numbers/small_share"].attrs["description"]
        assert "n_small" in s["per_task/one_block"].attrs["description"]
        # the statistics that were there are untouched
        np.testing.assert_array_equal(s["points/numbers/n_events"][:, 0], [np.sum(np.isin(
            task, np.flatnonzero(s["tasks/point"][:] == i))) for i in range(len(share))])
