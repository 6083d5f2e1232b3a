"""A reduction gives the summary of a committed reference, dataset for dataset: a refactor of the
reduction (or of what it reads) must cost nothing, as the kernel identity test asks of the kernel.

The catalog is made afresh from tests/data/summary_reference.toml (inertial events at b = 20, creep
episodes beside them at b = 15, two seeds each), reduced with the defaults, and compared with
tests/data/summary_reference.h5.gz: every dataset's name, dtype, shape and values (NaN equal to NaN),
and the options among the attributes. Not compared: what a run measures of its machine (the tasks'
wall time and events/s, and the record checksum that covers them) and the paths of the files.

A deliberate change of the summary or of the kernel's events moves the reference:

    .venv/bin/python -m tests.test_summary_identity write       (from the repository root)

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
MEASURED = {"tasks/wall_time", "tasks/events_per_second", "tasks/record_crc"}   # of the machine, not the physics
OPTIONS = ("format", "partial", "mu_c", "window", "b_cut", "bootstrap", "level", "blocks", "seed")


def summarize(workdir):
    """The summary of a fresh catalog of CONFIG, made in `workdir`: its path."""
    cat, out = Path(workdir) / "catalog.h5", Path(workdir) / "summary.h5"
    for args in (["ensemble", "run", str(CONFIG), "-o", str(cat)], ["analysis", "reduce", str(cat), "-o", str(out)]):
        res = run_bounded([sys.executable, "-m", *args], 600, cwd=ROOT, env=child_env())
        assert res.returncode == 0, res.stderr
    return out


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
    reference = tmp_path / "reference.h5"
    with gzip.open(REFERENCE, "rb") as src, open(reference, "wb") as dst:
        shutil.copyfileobj(src, dst)
    want, want_options = contents(reference)
    got, got_options = contents(summarize(tmp_path))
    assert sorted(got) == sorted(want), sorted(set(got) ^ set(want))
    differ = [name for name in sorted(want) if name not in MEASURED and not same(got[name], want[name])]
    assert not differ, f"datasets that differ from the reference: {differ}"
    assert got_options == want_options
    # what the comparison stands on: both laws' sides of the summary are there and not empty
    assert want["points/numbers/n_events"][:, 0].min() > 0 and want["points/numbers/n_creep"][:, 0].max() > 0


def write():
    with tempfile.TemporaryDirectory() as d:
        with open(summarize(d), "rb") as src, gzip.open(REFERENCE, "wb", compresslevel=9) as dst:
            shutil.copyfileobj(src, dst)
    print(f"wrote {REFERENCE.relative_to(ROOT)} ({REFERENCE.stat().st_size} bytes)")


if __name__ == "__main__":
    if sys.argv[1:] != ["write"]:
        raise SystemExit("usage: python -m tests.test_summary_identity write")
    write()
