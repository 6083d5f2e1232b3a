"""Adding a statistic touches one file (analysis/statistics/__init__.py says what it declares).

A copy of the analysis package gets one new module, analysis/statistics/one_block.py: the share of the
inertial events that slip exactly one block, from an additive table of its own. Nothing else is edited;
the copy's reduction of the committed catalog of tests/test_summary_identity.py then stores the table
and the number, describes both, and its estimate and interval are those of the events themselves.
"""
import shutil
import sys

import h5py
import numpy as np

from .processes import ROOT, child_env, run_bounded
from .test_summary_identity import CATALOG, gunzip

ONE_BLOCK = '''"""The share of the inertial events that slip exactly one block (a test's new statistic)."""
import numpy as np

from . import Number, Statistic, Table


def feed(acc, rows):
    if rows.ev is not None:
        acc.add("one_block", "n_one_block", rows.block, rows.ev["n_slipped"] == 1)


def estimate(u, opt):
    with np.errstate(invalid="ignore", divide="ignore"):
        return [u.column("one_block", "n_one_block") / u.column("numbers", "n_events")]


STATISTIC = Statistic(
    "one_block", 50,
    tables=(Table("one_block", "count", "events slipping one block", columns=("n_one_block",)),),
    numbers=(Number("one_block_share", "1", "share of the inertial events that slip exactly one block"),),
    feed=feed, estimate=estimate)
'''


def test_a_statistic_is_one_file(tmp_path):
    tree = tmp_path / "tree"
    for name in ("analysis", "ensemble"):
        shutil.copytree(ROOT / name, tree / name, ignore=shutil.ignore_patterns("__pycache__"))
    (tree / "analysis" / "statistics" / "one_block.py").write_text(ONE_BLOCK)
    cat = gunzip(CATALOG, tmp_path / "catalog.h5")
    out = tmp_path / "summary.h5"
    res = run_bounded([sys.executable, "-m", "analysis", "reduce", str(cat), "-o", str(out)], 600, cwd=tree,
                      env=child_env(PYTHONPATH=str(tree)))
    assert res.returncode == 0, res.stderr
    with h5py.File(cat, "r") as c, h5py.File(out, "r") as s:
        events = c["events"]
        inertial = events["kind"][:] == 0
        task, one = events["task"][:][inertial], events["n_slipped"][:][inertial] == 1
        table = s["per_task/one_block"][:]
        assert table.shape[:2] == s["per_task/mu"].shape[:2] and table.shape[2] == 1
        np.testing.assert_array_equal(table.sum(axis=(1, 2)), np.bincount(task[one], minlength=len(table)))
        share = s["points/numbers/one_block_share"][:]
        for i in range(len(share)):
            mine = np.isin(task, np.flatnonzero(s["tasks/point"][:] == i))
            assert share[i, 0] == one[mine].mean()
            assert share[i, 1] < share[i, 0] < share[i, 2]      # an interval from the bootstrap around it
        assert "one block" in s["points/numbers/one_block_share"].attrs["description"]
        assert "n_one_block" in s["per_task/one_block"].attrs["description"]
        # the statistics that were there are untouched
        np.testing.assert_array_equal(s["points/numbers/n_events"][:, 0], [np.sum(np.isin(
            task, np.flatnonzero(s["tasks/point"][:] == i))) for i in range(len(share))])
