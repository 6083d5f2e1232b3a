"""A reduction gives the summary of a committed reference, dataset for dataset: a refactor of the
reduction (or of what it reads) must cost nothing, as the kernel identity test asks of the kernel.

The committed catalog tests/data/summary_reference_catalog.h5.gz (made from
tests/data/summary_reference.toml: inertial events at b = 20, creep episodes beside them at b = 15, two
seeds each, 2400 rows) is reduced with the defaults and compared with tests/data/summary_reference.h5.gz:
every dataset's name, dtype, shape and values (NaN equal to NaN), and the options among the attributes.
The catalog is committed, not made afresh, so that the test sees the reduction alone (the kernel's events
are the kernel identity test's). Not compared: the paths of the files.

A deliberate change of the summary or of the kernel's events moves the reference:

    .venv/bin/python -m tests.test_summary_identity write [catalog]     (from the repository root)

(`catalog`: make the catalog afresh too, when the catalog's format or the kernel's events change)
and the commit says why (as tests/test_kernel_identity.py's REFERENCE moves).
"""
import gzip
import shutil
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

from .processes import ROOT, child_env, run_bounded

CONFIG = ROOT / "tests" / "data" / "summary_reference.toml"
REFERENCE = ROOT / "tests" / "data" / "summary_reference.h5.gz"
CATALOG = ROOT / "tests" / "data" / "summary_reference_catalog.h5.gz"
OPTIONS = ("format", "partial", "mu_c", "window", "b_cut", "bootstrap", "level", "blocks", "seed")


def python_m(*args):
    res = run_bounded([sys.executable, "-m", *map(str, args)], 600, cwd=ROOT, env=child_env())
    assert res.returncode == 0, res.stderr


def gunzip(src, dst):
    with gzip.open(src, "rb") as fin, open(dst, "wb") as fout:
        shutil.copyfileobj(fin, fout)
    return dst


def gzip_to(src, dst):
    with open(src, "rb") as fin, gzip.open(dst, "wb", compresslevel=9) as fout:
        shutil.copyfileobj(fin, fout)
    print(f"wrote {dst.relative_to(ROOT)} ({dst.stat().st_size} bytes)")


def contents(path):
    """({dataset name: array}, {option attribute: value}) of a summary."""
    data = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: data.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        options = {k: f.attrs[k] for k in OPTIONS if k in f.attrs}
    return data, options


def same(a, b):
    return (a.dtype == b.dtype and a.shape == b.shape
            and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))


def test_a_reduction_gives_the_committed_summary(tmp_path):
    want, want_options = contents(gunzip(REFERENCE, tmp_path / "reference.h5"))
    python_m("analysis", "reduce", gunzip(CATALOG, tmp_path / "catalog.h5"), "-o", tmp_path / "summary.h5")
    got, got_options = contents(tmp_path / "summary.h5")
    assert sorted(got) == sorted(want), sorted(set(got) ^ set(want))
    differ = [name for name in sorted(want) if not same(got[name], want[name])]
    assert not differ, f"datasets that differ from the reference: {differ}"
    assert got_options == want_options
    # what the comparison stands on: both laws' sides of the summary are there and not empty
    assert want["points/numbers/n_events"][:, 0].min() > 0 and want["points/numbers/n_creep"][:, 0].max() > 0


def write(new_catalog):
    """The reference summary of the committed catalog; with `catalog`, of a fresh catalog of CONFIG."""
    with tempfile.TemporaryDirectory() as d:
        cat, out = Path(d) / "catalog.h5", Path(d) / "summary.h5"
        if new_catalog:
            python_m("ensemble", "run", CONFIG, "-o", cat)
            gzip_to(cat, CATALOG)
        else:
            gunzip(CATALOG, cat)
        python_m("analysis", "reduce", cat, "-o", out)
        gzip_to(out, REFERENCE)


if __name__ == "__main__":
    if sys.argv[1:] not in (["write"], ["write", "catalog"]):
        raise SystemExit("usage: python -m tests.test_summary_identity write [catalog]")
    write(sys.argv[2:] == ["catalog"])
