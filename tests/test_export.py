"""Getting at the data: `python -m analysis export`, the table API (analysis/export.py) and the
`description` attribute of every dataset of a catalog and of a summary.

The catalogs are synthetic and written with the project's own writers (tests/test_reduction.py's
write_catalog), with failed tasks whose errors hold commas, quotes, a '#' and a newline. CSV
files are read back the way their first line says (numpy.genfromtxt with skip_header, the csv
module for text, pandas when installed) and compared exactly: floats are written to read back
to the same float64.
"""
import csv
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from analysis import export, summary
from ensemble.store import reader, schema, writers
from ensemble.store.errors import CatalogError
from ensemble.config import loads
from ensemble.sweep import task_list

from .processes import package_copy
from .test_reduction import CONFIG, N_CHAIN, ROOT, write_catalog

TIMEOUT = 300    # seconds for one subprocess (each takes a few)
SWEEP = "nu = [1.0, 0.5]\nb = [20.0, 30.0]"
WRITTEN = [400, 0, 250, 400, 3, 0, 137, 400]   # 4 points x 2 seeds: empty tasks, partly written ones;
# point 2 (3 events) has no recurrence: NaN densities and numbers
ERRORS = {   # failed task -> its error: as the runner words one (commas), and one with more to quote
    2: "task 2 event 255: step beyond the stability limit of RK4 (method=rk4, dt=0.001, rtol=1e-05)",
    6: 'task 6: RuntimeError: "dt" # 3\nsecond line',
}


def env():
    return dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1",
                NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))


def analysis(*args):
    return subprocess.run([sys.executable, "-m", "analysis", *map(str, args)], capture_output=True, text=True,
                          env=env(), cwd=ROOT, timeout=TIMEOUT)


def ok(res):
    assert res.returncode == 0, res.stderr
    return res


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A catalog (one task failed), its summary, and both exported to CSV by the command line."""
    from mpi4py import MPI
    d = tmp_path_factory.mktemp("export")
    cat = d / "cat.h5"
    write_catalog(cat, CONFIG.format(N=N_CHAIN, sweep=SWEEP, seeds=2, seed=0), WRITTEN, seed=5)
    writer = writers.Rank0Writer(str(cat), MPI.COMM_SELF)
    for task, error in ERRORS.items():
        writer.fail(task, error)
    writer.close()
    # --blocks 1: each task is one resampling unit (the bootstrap noise of the few synthetic
    # recurrences stays low enough for peaks in two points)
    ok(analysis("reduce", cat, "-o", d / "cat.summary.h5", "--partial", "--mu-bins=-1:7:32", "--tnu-bins=0:20:40",
                "--mu-c", "4", "--window", "3", "--bootstrap", "50", "--blocks", "1"))
    ok(analysis("export", cat, "-o", d / "cat_csv", "--partial"))   # its tasks are not all finished
    ok(analysis("export", d / "cat.summary.h5", "--format", "csv", "-o", d / "sum_csv"))
    return d


def genfromtxt(path):
    """A CSV of the export read with numpy, the way its first line says."""
    with open(path, encoding="utf-8") as fh:
        first = fh.readline()
    skip = int(re.search(r"skip_header=(\d+)", first).group(1))
    use = re.search(r"usecols=range\((\d+)\)", first)
    return np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8",
                                       comments=None, skip_header=skip,
                                       usecols=range(int(use.group(1))) if use else None))


def csv_rows(path):
    """(column names, rows as lists of text) with the csv module, the comment lines skipped."""
    with open(path, encoding="utf-8", newline="") as fh:
        lines = [line for line in fh if not line.startswith("#")]
    rows = list(csv.reader(lines))
    return rows[0], rows[1:]


def assert_same(got, want, names=None):
    """Structured arrays (or dicts of arrays) equal column by column, NaN equal to NaN, exactly."""
    for name in names or want.dtype.names:
        np.testing.assert_array_equal(got[name], want[name], err_msg=name, strict=False)
        if np.asarray(want[name]).dtype.kind in "fiub":
            assert np.asarray(got[name]).dtype.kind == np.asarray(want[name]).dtype.kind, name


# -- the structured-array API against the files ------------------------------------------------

def test_api_events_and_tasks_are_the_catalogs(files):
    events, tasks, _ = reader.read(files / "cat.h5")
    ev = export.events(files / "cat.h5")
    assert list(ev.dtype.names) == list(schema.EVENT_FIELDS)
    for name, dtype in schema.EVENT_FIELDS.items():
        assert ev[name].dtype == dtype
        np.testing.assert_array_equal(ev[name], events[name], err_msg=name)
    tk = export.tasks(files / "cat.h5")
    np.testing.assert_array_equal(tk["task"], np.arange(len(WRITTEN)))
    np.testing.assert_array_equal(tk["events_written"], WRITTEN)
    for name in ("point", "seed_index", "N", "l", "nu", "a", "b", "c", "events_done", "status", "rank",
                 "wall_time", "events_per_second", "seed_entropy", "spawn_key"):
        np.testing.assert_array_equal(tk[name], tasks[name], err_msg=name)
    assert list(tk["error"]) == [ERRORS.get(k, "").replace("\n", " ") for k in range(len(WRITTEN))]  # one line
    assert list(np.flatnonzero(tk["status"] == schema.FAILED)) == list(ERRORS)
    cfg = loads(CONFIG.format(N=N_CHAIN, sweep=SWEEP, seeds=2, seed=0))
    assert set(tk["integrator_method"]) == {cfg.integrator.method}
    for key in ("dt", "rtol", "atol", "max_step", "max_duration"):
        assert tk[f"integrator_{key}"].dtype == np.float64
        assert set(tk[f"integrator_{key}"]) == {getattr(cfg.integrator, key)}, key


def test_api_streams_the_catalog_in_verified_chunks(files, tmp_path):
    """iter_events gives chunks of at most `chunk` rows, tasks in order; a corrupt row fails the
    export with the catalog's message, and nothing is written."""
    events, _, _ = reader.read(files / "cat.h5")
    parts = list(export.iter_events(files / "cat.h5", chunk=7))
    assert max(len(p) for p in parts) == 7 and len(parts) >= sum(WRITTEN) // 7
    assert_same(np.concatenate(parts), events, list(schema.EVENT_FIELDS))
    bad = shutil.copy(files / "cat.h5", tmp_path / "bad.h5")
    with h5py.File(bad, "r+") as h5:       # in range, so only the task's checksum can tell
        h5["events/duration"][3 * 400 + 150] += 1.0
    with pytest.raises(CatalogError, match="task 3: its 400 events fail their checksum"):
        export.write(bad, tmp_path / "out", chunk=7, partial=True)
    assert not (tmp_path / "out").exists()          # the folder it made goes too
    (tmp_path / "out").mkdir()                      # one that was there stays, empty
    res = analysis("export", bad, "-o", tmp_path / "out", "--partial")
    assert res.returncode == 1 and "task 3: its 400 events fail their checksum" in res.stderr
    assert os.listdir(tmp_path / "out") == []


def test_api_curves_numbers_peaks_are_the_summarys(files):
    s = summary.read(files / "cat.summary.h5")
    cu = export.curves(files / "cat.summary.h5")
    for curve, (bins, *_) in summary.CURVES.items():
        edges = s[f"bins/{bins}"]
        for point in range(len(s["points/N"])):
            rows = cu[(cu["curve"] == curve) & (cu["point"] == point)]
            np.testing.assert_array_equal(rows["bin"], np.arange(len(edges) - 1))
            np.testing.assert_array_equal(rows["edge_lo"], edges[:-1])
            np.testing.assert_array_equal(rows["edge_hi"], edges[1:])
            np.testing.assert_array_equal(rows["center"], 0.5 * (edges[1:] + edges[:-1]))
            for part, column in (("density", "density"), ("lo", "density_lo"), ("hi", "density_hi")):
                np.testing.assert_array_equal(rows[column], s[f"points/{curve}_{part}"][point], err_msg=column)
    assert len(cu) == len(s["points/N"]) * sum(len(s[f"bins/{bins}"]) - 1 for bins, *_ in summary.CURVES.values())
    nb = export.numbers(files / "cat.summary.h5")
    np.testing.assert_array_equal(nb["point"], np.arange(len(s["points/N"])))
    for name in ("N", "l", "nu", "a", "b", "c", "method", "units"):
        np.testing.assert_array_equal(nb[name], s[f"points/{name}"], err_msg=name)
    for name in summary.NUMBER_MEANINGS:
        for j, suffix in enumerate(("", "_lo", "_hi")):
            np.testing.assert_array_equal(nb[name + suffix], s[f"points/numbers/{name}"][:, j], err_msg=name + suffix)
    pk = export.table(files / "cat.summary.h5", "peaks")
    found = np.isfinite(s["points/peaks"][..., 0])
    assert len(pk) == found.sum() >= 2 and not found[2].any()     # point 2 has no peak: no row
    np.testing.assert_array_equal(np.stack([pk["tnu"], pk["tnu_lo"], pk["tnu_hi"]], axis=1),
                                  s["points/peaks"][found])


def test_peaks_table_of_several_peaks_per_point(files, tmp_path):
    """points/peaks (points, most peaks, 3) padded with NaN rows -> one row per peak, in order.
    (The synthetic catalogs have at most one significant peak per point: these are set by hand.)"""
    nan = np.nan
    peaks = np.array([[[5.0, 4.5, 5.5], [12.0, 11.0, 13.5], [nan, nan, nan]],
                      [[3.0, nan, nan], [nan, nan, nan], [nan, nan, nan]],
                      [[nan, nan, nan]] * 3,
                      [[2.0, 1.5, 2.5], [7.0, 6.0, 7.5], [15.0, 14.0, 16.0]]])
    path = shutil.copy(files / "cat.summary.h5", tmp_path / "peaks.summary.h5")
    with h5py.File(path, "r+") as h5:
        del h5["points/peaks"]
        h5["points/peaks"] = peaks
        summary.seal(h5)        # (edited by hand: its checksums again)
    pk = export.table(path, "peaks")
    assert list(zip(pk["point"], pk["peak"])) == [(0, 0), (0, 1), (1, 0), (3, 0), (3, 1), (3, 2)]
    np.testing.assert_array_equal(np.stack([pk["tnu"], pk["tnu_lo"], pk["tnu_hi"]], axis=1),
                                  peaks[np.isfinite(peaks[..., 0])])


def test_every_summary_dataset_per_point_is_exported(files):
    """Each /points dataset reaches a table (a new one must be added to the export)."""
    s = summary.read(files / "cat.summary.h5")
    tables = {t: export.columns(files / "cat.summary.h5", t) for t in export.SUMMARY_TABLES}
    covered = {f"points/{c}" for c in tables["numbers"]} | {"points/peaks"}
    covered |= {"points/seismicity_rate"} if "rate" in tables["seismicity"] else set()
    covered |= {f"points/numbers/{c}" for c in tables["numbers"]}
    covered |= {f"points/{c}_{p}" for c in summary.CURVES for p in ("density", "lo", "hi")}
    assert {k for k in s if k.startswith("points/")} <= covered
    assert set(export.curves(files / "cat.summary.h5")["curve"]) == set(summary.CURVES)


def test_every_column_has_a_unit_and_a_meaning(files):
    for path, tables in ((files / "cat.h5", export.CATALOG_TABLES),
                         (files / "cat.summary.h5", export.SUMMARY_TABLES)):
        for table in tables:
            for name, (unit, meaning) in export.columns(path, table).items():
                assert unit.strip() and meaning.strip(), (table, name)


# -- CSV -----------------------------------------------------------------------------------------

def test_catalog_csv_round_trips_exactly(files):
    events, tasks, _ = reader.read(files / "cat.h5")
    ev = genfromtxt(files / "cat_csv" / "events.csv")
    assert list(ev.dtype.names) == list(schema.EVENT_FIELDS)
    assert_same(ev, events, list(schema.EVENT_FIELDS))
    tk = genfromtxt(files / "cat_csv" / "tasks.csv")
    for name in ("point", "seed_index", "N", "l", "nu", "a", "b", "c", "events_written", "events_done",
                 "status", "rank", "wall_time", "events_per_second", "seed_entropy", "spawn_key"):
        np.testing.assert_array_equal(tk[name], tasks[name], err_msg=name)
        assert tk[name].dtype.kind == tasks[name].dtype.kind, name
    names, rows = csv_rows(files / "cat_csv" / "tasks.csv")
    assert names[-1] == "error" and len(rows) == len(WRITTEN)
    assert [r[-1] for r in rows] == [ERRORS.get(k, "").replace("\n", " ") for k in range(len(WRITTEN))]
    assert all(len(r) == len(names) for r in rows)


def test_summary_csv_round_trips_exactly(files):
    s = summary.read(files / "cat.summary.h5")
    cu = genfromtxt(files / "sum_csv" / "curves.csv")
    for curve in summary.CURVES:
        for part, column in (("density", "density"), ("lo", "density_lo"), ("hi", "density_hi")):
            got = cu[column][cu["curve"] == curve].reshape(len(s["points/N"]), -1)
            np.testing.assert_array_equal(got, s[f"points/{curve}_{part}"], err_msg=f"{curve} {part}")
    assert np.isnan(cu["density"]).any() and np.isnan(cu["density_lo"]).any()   # NaN written and read
    nb = genfromtxt(files / "sum_csv" / "numbers.csv")
    for name in ("N", "l", "nu", "a", "b", "c", "method", "units"):
        np.testing.assert_array_equal(nb[name], s[f"points/{name}"], err_msg=name)
    for name in summary.NUMBER_MEANINGS:
        got = np.stack([nb[name + suffix] for suffix in ("", "_lo", "_hi")], axis=1)
        np.testing.assert_array_equal(got, s[f"points/numbers/{name}"], err_msg=name)
    pk = genfromtxt(files / "sum_csv" / "peaks.csv")
    np.testing.assert_array_equal(np.stack([pk["tnu"], pk["tnu_lo"], pk["tnu_hi"]], axis=1),
                                  s["points/peaks"][pk["point"], pk["peak"]])


@pytest.mark.parametrize("source,directory,tables", [
    ("cat.h5", "cat_csv", export.CATALOG_TABLES), ("cat.summary.h5", "sum_csv", export.SUMMARY_TABLES)])
def test_csv_holds_what_the_api_returns(files, source, directory, tables):
    """Same columns in the same order, same values (numbers read with numpy, text with csv)."""
    assert sorted(os.listdir(files / directory)) == sorted(f"{t}.csv" for t in tables)
    for table in tables:
        want = export.table(files / source, table)
        path = files / directory / f"{table}.csv"
        names, rows = csv_rows(path)
        assert names == list(want.dtype.names) and len(rows) == len(want), table
        got = genfromtxt(path)
        for j, name in enumerate(names):
            if want[name].dtype.kind == "U":
                assert [r[j] for r in rows] == list(want[name]), (table, name)
            else:
                assert_same(got, want, [name])
        lines = path.read_text(encoding="utf-8").splitlines()
        count = int(re.search(r"skip_header=(\d+)", lines[0]).group(1))
        assert all(line.startswith("# ") for line in lines[:count]) and lines[count] == ",".join(names)
        start = lines.index("# column: unit, meaning") + 1
        assert [line[2:].split(":", 1)[0] for line in lines[start:count]] == names, table   # one line each


def test_tables_of_a_partial_reduction_say_so(files):
    """The catalog holds unfinished tasks (reduced with --partial): each summary table's header
    states it, as the report's first line does."""
    partial = summary.read(files / "cat.summary.h5")["attrs"]["partial"]
    assert partial.startswith("PARTIAL")
    for table in ("curves", "numbers", "peaks"):
        lines = (files / "sum_csv" / f"{table}.csv").read_text(encoding="utf-8").splitlines()
        assert sum(line.startswith("# reduced from ") and line.endswith("; " + partial) for line in lines) == 1


def test_export_of_an_unfinished_run_needs_partial_as_reduce_does(files, tmp_path):
    """Issue 26, item 11: an unfinished run exported with exit 0, and its headers did not say so.
    Refused as reduce refuses it (its words with export's verb, exit 1), nothing written; a run's
    *.partial too, even with every task finished (the run has not renamed it: it may go on)."""
    red = analysis("reduce", files / "cat.h5", "-o", tmp_path / "s.h5")
    res = analysis("export", files / "cat.h5", "-o", tmp_path / "out")
    assert red.returncode == res.returncode == 1
    assert res.stderr.strip().splitlines() == [red.stderr.strip().replace("reduce what it holds",
                                                                          "export what it holds")]
    assert "(5 of 8 tasks unfinished)" in res.stderr and not (tmp_path / "out").exists()
    whole = tmp_path / "whole.h5"
    write_catalog(whole, CONFIG.format(N=N_CHAIN, sweep="nu = [1.0]", seeds=2, seed=0), [400, 400], seed=2)
    ok(analysis("export", whole, "-o", tmp_path / "whole_csv"))
    assert "PARTIAL" not in (tmp_path / "whole_csv" / "tasks.csv").read_text()
    running = whole.rename(tmp_path / "whole.h5.partial")
    res = analysis("export", running, "-o", tmp_path / "out")
    assert res.returncode == 1 and res.stderr.strip().splitlines() == [
        f"error: {running} is an unfinished run (named *.partial); continue it with `python -m ensemble resume "
        f"{whole}`, or export what it holds with --partial"]
    ok(analysis("export", running, "-o", tmp_path / "out", "--partial"))
    for table in ("events", "tasks"):
        lines = (tmp_path / "out" / f"{table}.csv").read_text().splitlines()
        assert "# PARTIAL export of an unfinished run (named *.partial): 800 of 800 events (100.0%)" in lines


def test_tables_of_an_unfinished_run_say_so(files):
    """With --partial, every table's header states the run unfinished: tasks, events of expected."""
    _, tasks, _ = reader.read(files / "cat.h5")
    assert np.count_nonzero((tasks["status"] != schema.FINISHED) | (tasks["events_written"] < 400)) == 5
    line = (f"# PARTIAL export of an unfinished run (5 of 8 tasks unfinished): {sum(WRITTEN)} of {8 * 400} events "
            f"({100 * sum(WRITTEN) / (8 * 400):.1f}%)")
    for table in ("events", "tasks"):
        lines = (files / "cat_csv" / f"{table}.csv").read_text(encoding="utf-8").splitlines()
        count = int(re.search(r"skip_header=(\d+)", lines[0]).group(1))
        assert lines[:count].count(line) == 1, table


def test_export_refuses_to_overwrite(files, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "tasks.csv").write_text("mine\n")
    res = analysis("export", files / "cat.h5", "-o", out, "--partial")
    assert res.returncode == 2   # a usage error, as `ensemble run` says of an existing catalog
    assert res.stderr.strip().splitlines() == [
        f"error: {out / 'tasks.csv'}: table exists (use --force to overwrite it)"]
    assert sorted(os.listdir(out)) == ["tasks.csv"] and (out / "tasks.csv").read_text() == "mine\n"
    ok(analysis("export", files / "cat.h5", "-o", out, "--force", "--partial"))
    assert (out / "tasks.csv").read_text() == (files / "cat_csv" / "tasks.csv").read_text()
    assert (out / "events.csv").read_text() == (files / "cat_csv" / "events.csv").read_text()


@pytest.mark.parametrize("name,words", [
    ("cfg.toml", "is a run config (TOML), not an event catalog (run it first"),
    ("dir", "is a directory, not an event catalog"),
    ("nope.h5", "does not exist"),
    ("noise.h5", "is a damaged or truncated HDF5 file"),
    ("other.h5", "is an HDF5 file but neither an event catalog nor a reduction summary"),
])
def test_export_of_a_wrong_file_is_one_line(files, tmp_path, name, words):
    (tmp_path / "cfg.toml").write_text(CONFIG.format(N=N_CHAIN, sweep=SWEEP, seeds=2, seed=0))
    (tmp_path / "dir").mkdir()
    (tmp_path / "noise.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 8)
    with h5py.File(tmp_path / "other.h5", "w") as h5:
        h5["x"] = [1, 2, 3]
    res = analysis("export", tmp_path / name, "-o", tmp_path / "out")
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {tmp_path / name} {words}"), res.stderr
    assert not (tmp_path / "out").exists()


def test_api_given_the_other_kind_says_so(files):
    with pytest.raises(CatalogError, match="not an event catalog .give the catalog it was reduced from"):
        export.events(files / "cat.summary.h5")
    with pytest.raises(summary.SummaryError, match="not a reduction summary .reduce it first"):
        export.numbers(files / "cat.h5")
    with pytest.raises(ValueError, match="its tables are curves, numbers, peaks, seismicity, not events"):
        export.columns(files / "cat.summary.h5", "events")


# -- pandas (optional) -----------------------------------------------------------------------------

def test_without_pandas_a_dataframe_is_a_clear_error(files, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)     # import pandas now raises ImportError
    with pytest.raises(ImportError, match=r"pandas is not installed \(it is optional"):
        export.table(files / "cat.summary.h5", "peaks", frame=True)


def test_pandas_reads_the_csv_as_the_api_returns_it(files):
    pandas = pytest.importorskip("pandas", reason="pandas is optional and not installed here; the "
                                                  "structured-array API and the CSV are tested without it")
    for source, directory, tables in (("cat.h5", "cat_csv", export.CATALOG_TABLES),
                                      ("cat.summary.h5", "sum_csv", export.SUMMARY_TABLES)):
        for table in tables:
            want = export.table(files / source, table, frame=True)
            assert isinstance(want, pandas.DataFrame)
            got = pandas.read_csv(files / directory / f"{table}.csv", comment="#")
            assert list(got.columns) == list(want.columns), table
            for name in want.columns:
                if want[name].dtype.kind in "fiub":
                    assert got[name].dtype.kind == want[name].dtype.kind, (table, name)
                    np.testing.assert_array_equal(got[name].to_numpy(), want[name].to_numpy(), err_msg=name)
                else:    # an empty text reads as NaN
                    assert list(got[name].fillna("")) == list(want[name]), (table, name)


# -- descriptions ------------------------------------------------------------------------------------

# run.branch = false, output.history = 0 (tests/test_histories.py checks /histories)
UNBRANCHED = [name for name in schema.DATASETS if not name.startswith(("spinup/", "histories/"))]


def descriptions(path):
    """{dataset: its description attribute or None} of every dataset of an HDF5 file."""
    found = {}
    with h5py.File(path, "r") as h5:
        h5.visititems(lambda name, obj: found.__setitem__(name, obj.attrs.get("description"))
                      if isinstance(obj, h5py.Dataset) else None)
    return found


def assert_described(path, table):
    found = descriptions(path)
    missing = sorted(name for name, text in found.items() if not (isinstance(text, str) and text.strip()))
    assert not missing, f"datasets without a description: {missing}"
    assert all("\n" not in text for text in found.values())
    for name, text in found.items():
        assert text == schema.description(table[name]), name


def test_every_dataset_of_a_catalog_and_a_summary_is_described(files):
    assert_described(files / "cat.h5", schema.DATASETS)
    # no line for a dataset gone (/spinup exists with run.branch only: tests/test_branch.py)
    assert set(descriptions(files / "cat.h5")) == set(UNBRANCHED)
    assert_described(files / "cat.summary.h5", summary.DATASETS)
    # every task column of the catalog is the summary's, but the geometry's (the analysis reads chains only so far)
    assert {name.split("/", 1)[1] for name in schema.DATASETS if name.startswith("tasks/")} - set(
        schema.GEOMETRY_TASKS) <= set(
        name.split("/", 1)[1] for name in descriptions(files / "cat.summary.h5") if name.startswith("tasks/"))


def test_a_catalog_without_descriptions_still_reads_and_exports(files, tmp_path):
    """Catalogs written before the attribute existed."""
    old = shutil.copy(files / "cat.h5", tmp_path / "old.h5")
    with h5py.File(old, "r+") as h5:
        for name in UNBRANCHED:
            del h5[name].attrs["description"]
    assert set(descriptions(old).values()) == {None}
    events, tasks, _ = reader.read(old)
    assert len(events["t"]) == sum(WRITTEN)
    export.write(old, tmp_path / "out", partial=True)
    assert (tmp_path / "out" / "events.csv").read_text().split("\n", 2)[2] == (
        (files / "cat_csv" / "events.csv").read_text().split("\n", 2)[2])   # all but the source's name


CREATE = """
import sys
from mpi4py import MPI
from ensemble.store import writers
from ensemble.config import loads
from ensemble.run.trajectory import integrator_text
from ensemble.sweep import task_list
cfg = loads(sys.argv[2])
writer = writers.ParallelWriter(sys.argv[1], MPI.COMM_WORLD, cfg, task_list(cfg), integrator_text(cfg.integrator))
writer.close()
"""


@pytest.mark.mpi
@pytest.mark.parallel_hdf5
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="needs mpiexec")
def test_the_parallel_writer_describes_every_dataset(tmp_path):
    """A catalog created collectively by 2 ranks through mpio carries the same descriptions."""
    path = tmp_path / "mpio.h5"
    text = CONFIG.format(N=N_CHAIN, sweep=SWEEP, seeds=2, seed=0)
    # a few seconds; an attribute written by one rank only would hang the collective close
    res = subprocess.run(["mpiexec", "-n", "2", sys.executable, "-c", CREATE, str(path), text],
                         capture_output=True, text=True, env=env(), cwd=ROOT, timeout=120)
    assert res.returncode == 0, res.stderr
    assert_described(path, schema.DATASETS)
    assert set(descriptions(path)) == set(UNBRANCHED)
    _, tasks, _ = reader.read_tasks(path)
    assert len(tasks["point"]) == len(task_list(loads(text)))


TSV = '''"""Tab-separated tables (a test's export format): a row of column names, then the rows."""
from ensemble import space


def write_tsv(path, name, table, source, settings=""):
    def text():
        yield "\\t".join(table.columns) + "\\n"
        for part in table.parts:
            for row in part.tolist():
                yield "\\t".join(map(str, row)) + "\\n"
    space.write_file(path, text(), f"the table {name}")


FORMAT = (".tsv", write_tsv)
'''


def test_an_export_format_is_one_file(files, tmp_path):
    """A copy of the package with one new module, analysis/export_tsv.py: `export --format tsv` writes every table
    of the catalog and of the summary as .tsv files holding what the API returns; without the file, `--format tsv`
    is refused (exit 2)."""
    tree = tmp_path / "tree"
    package_copy(tree, "analysis", "ensemble")
    (tree / "analysis" / "export_tsv.py").write_text(TSV)

    def in_tree(*args):
        return subprocess.run([sys.executable, "-m", "analysis", *map(str, args)], capture_output=True, text=True,
                              env={**env(), "PYTHONPATH": str(tree)}, cwd=tree, timeout=TIMEOUT)
    for source, tables, name in ((files / "cat.h5", export.CATALOG_TABLES, "tasks"),
                                 (files / "cat.summary.h5", export.SUMMARY_TABLES, "numbers")):
        out = tmp_path / source.name
        ok(in_tree("export", source, "--format", "tsv", "-o", out, "--partial"))
        assert sorted(os.listdir(out)) == sorted(f"{t}.tsv" for t in tables)
        want = export.table(source, name)
        lines = (out / f"{name}.tsv").read_text().splitlines()
        assert lines[0].split("\t") == list(want.dtype.names) and len(lines) == 1 + len(want)
    res = analysis("export", files / "cat.h5", "--format", "tsv", "-o", tmp_path / "none")
    assert res.returncode == 2 and "tsv" in res.stderr and not (tmp_path / "none").exists()


def test_an_export_that_fails_at_a_later_table_leaves_nothing(files, tmp_path, monkeypatch):
    """The first table written whole, the second failing (a disk filling up between them): neither the first
    table's file (written beside its name) nor the folder the export made is left."""
    suffix, write_csv = export.FORMATS["csv"]

    def fails_at_the_tasks(path, name, table, source, settings=""):
        if name == "tasks":
            raise OSError(28, "No space left on device")
        write_csv(path, name, table, source, settings)
    monkeypatch.setitem(export.FORMATS, "csv", (suffix, fails_at_the_tasks))
    with pytest.raises(OSError, match="No space left"):
        export.write(files / "cat.h5", tmp_path / "out", partial=True)
    assert not (tmp_path / "out").exists()
