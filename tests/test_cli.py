"""Command line, config validation and the catalog written by a serial run."""
import sys

import h5py
import mpi4py
import numba
import numpy as np
import pytest

from ensemble import cli
from ensemble.store import reader, schema, writers
from ensemble.config import loads

from .conftest import run_cli, write_config
from .processes import ROOT, child_env, run_bounded


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    cfg = write_config(d / "cfg.toml", sweep={"b": [20.0, 30.0]}, run={"seeds": 2, "events": 30},
                       integrator={"dt": 5e-4}, output={"batch": 8})   # several commits per task
    res = run_cli("run", cfg)
    assert res.returncode == 0, res.stderr
    (d / "run.log").write_text(res.stdout)
    return d, cfg


def test_catalog_schema_and_content(small_run):
    d, cfg = small_run
    events, tasks, attrs = reader.read(d / "cfg.h5")
    assert len(tasks["point"]) == 4 and list(tasks["events_written"]) == [30] * 4
    assert list(tasks["b"]) == [20.0, 20.0, 30.0, 30.0] and list(tasks["seed_index"]) == [0, 1, 0, 1]
    assert len(events["t"]) == 120
    assert loads(attrs["config"]).run.events == 30
    for k in range(4):
        mine = events["task"] == k
        assert np.count_nonzero(mine) == 30
        assert np.all(np.diff(events["t"][mine]) > 0)           # time order within a task
    for k in (0, 2):    # the two seeds of a point are independent realisations
        assert not np.array_equal(events["slip"][events["task"] == k], events["slip"][events["task"] == k + 1])
    np.testing.assert_allclose(events["mu"], np.log10(events["slip"]))
    assert np.all(events["first"] <= events["epicenter"]) and np.all(events["epicenter"] <= events["last"])
    assert np.all(events["n_slipped"] <= events["last"] - events["first"] + 1)
    assert np.array_equal(events["boundary"], (events["first"] == 0) | (events["last"] == 59))
    assert np.all(events["duration"] > 0)
    with h5py.File(d / "cfg.h5") as h5:
        assert set(h5["events"]) == set(schema.EVENT_FIELDS)
        assert h5["events"]["boundary"].dtype == np.bool_


def test_same_seed_same_catalog_other_seed_differs(small_run, tmp_path):
    d, cfg = small_run
    assert run_cli("run", cfg, "-o", tmp_path / "again.h5").returncode == 0
    assert run_cli("run", cfg, "-o", tmp_path / "other.h5", "--set", "run.seed=5").returncode == 0
    a, _, _ = reader.read(d / "cfg.h5")
    b, _, _ = reader.read(tmp_path / "again.h5")
    c, _, _ = reader.read(tmp_path / "other.h5")
    for name in schema.EVENT_FIELDS:
        np.testing.assert_array_equal(a[name], b[name])
    assert not np.array_equal(a["slip"], c["slip"])


def test_the_transient_is_exactly_run_transient_events_whatever_the_kernel_calls(tmp_path):
    """A task records its events from event run.transient on: its rows are the tail of a run of the same seed
    that discards nothing. output.batch = 1 makes every kernel call one event long, so that a call ends
    after every event, the last transient one included, whatever the machine's speed. (The calls' length
    otherwise follows the wall clock, and an off-by-one in the transient shows only where a call happens
    to end one event early.)"""
    transient, events = 7, 12
    one = write_config(tmp_path / "one.toml", run={"seeds": 1, "events": events, "transient": transient},
                       output={"batch": 1})
    none = write_config(tmp_path / "none.toml", run={"seeds": 1, "events": transient + events, "transient": 0})
    for cfg in (one, none):
        res = run_cli("run", cfg)
        assert res.returncode == 0, res.stderr
    a, _, attrs = reader.read(tmp_path / "one.h5")
    b, _, _ = reader.read(tmp_path / "none.h5")
    assert attrs["transient"] == transient and len(a["t"]) == events
    for name in schema.EVENT_FIELDS:
        np.testing.assert_array_equal(a[name], b[name][transient:], err_msg=name)


def test_refuses_to_overwrite_without_force(small_run):
    d, cfg = small_run
    before = (d / "cfg.h5").read_bytes()
    res = run_cli("run", cfg)
    assert res.returncode == 2 and "exists" in res.stderr and "--force" in res.stderr
    assert (d / "cfg.h5").read_bytes() == before


def test_status_summarises_a_finished_catalog(small_run):
    d, cfg = small_run
    res = run_cli("status", d / "cfg.h5")
    assert res.returncode == 0, res.stderr
    assert "complete" in res.stdout and "tasks finished 4/4, events recorded 120/120" in res.stdout
    assert res.stdout.count(" finished     0 ") == 4   # status and rank columns
    res = run_cli("status", d / "missing.h5")
    assert res.returncode == 1 and "missing.h5" in res.stderr


def test_validate_prints_resolved_config_and_tasks(small_run):
    d, cfg = small_run
    res = run_cli("validate", cfg, "--set", "run.seeds=3")
    assert res.returncode == 0, res.stderr
    assert loads(res.stdout.split("# ")[0]).run.seeds == 3
    assert "# 6 tasks" in res.stdout and "task 5: point 1 seed 2" in res.stdout


def expected_stack():
    """The mpi and hdf5 lines validate, the run log and the catalog give in this environment."""
    from mpi4py import MPI
    library = " ".join(MPI.Get_library_version().splitlines()[0].split())
    mpi = "with" if writers.has_parallel_hdf5() else "without"
    return [f"mpi: {library} (MPI {'.'.join(map(str, MPI.Get_version()))}, mpi4py {mpi4py.__version__})",
            f"hdf5: {h5py.version.hdf5_version} {mpi} MPI (h5py {h5py.__version__})"]


def test_validate_names_the_mpi_the_hdf5_and_the_writer(small_run):
    d, cfg = small_run
    res = run_cli("validate", cfg)
    assert res.returncode == 0, res.stderr
    more = ("parallel HDF5 (mpio), independent writes" if writers.has_parallel_hdf5() else
            "serial HDF5 on rank 0, rows sent by message (h5py has no MPI)")
    assert res.stdout.strip().splitlines()[-3:] == [
        *("# " + line for line in expected_stack()), f"# writer: auto -> 1 rank: serial HDF5; more ranks: {more}"]


def test_validate_without_parallel_hdf5(small_run, monkeypatch, capsys):
    """As on the wheel stack: 'auto' says why more ranks use rank0, 'parallel' fails naming the key."""
    d, cfg = small_run
    monkeypatch.setattr(writers, "has_parallel_hdf5", lambda: False)
    assert cli.main(["validate", str(cfg)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-2].startswith("# hdf5: ") and lines[-2].endswith(f" without MPI (h5py {h5py.__version__})")
    assert lines[-1] == ("# writer: auto -> 1 rank: serial HDF5; "
                         "more ranks: serial HDF5 on rank 0, rows sent by message (h5py has no MPI)")
    assert cli.main(["validate", str(cfg), "--set", 'output.writer="parallel"']) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith("error: output.writer = 'parallel' needs h5py built with MPI support")


def test_run_refuses_the_parallel_writer_without_parallel_hdf5(tmp_path):
    """The run itself refuses, as a config error (exit 2, one line), before creating anything."""
    cfg = write_config(tmp_path / "c.toml")
    code = ("import sys; from ensemble import cli; from ensemble.store import writers; "
            "writers.has_parallel_hdf5 = lambda: False; "
            f"sys.exit(cli.main(['run', {str(cfg)!r}, '--set', 'output.writer=\"parallel\"']))")
    res = run_bounded([sys.executable, "-c", code], 600, cwd=ROOT, env=child_env())
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: output.writer = 'parallel' needs h5py")
    assert not (tmp_path / "c.h5").exists() and not (tmp_path / "c.h5.partial").exists()


def test_run_log_and_catalog_name_the_stack(small_run):
    d, cfg = small_run
    log = (d / "run.log").read_text().splitlines()
    start = log.index(f"writing {d / 'cfg.h5.partial'} with 1 rank(s): serial HDF5")
    assert log[start - 2:start] == expected_stack()
    assert sum(line.startswith(("mpi: ", "hdf5: ")) for line in log) == 2
    _, _, attrs = reader.read_tasks(d / "cfg.h5")
    python = ".".join(map(str, sys.version_info[:3]))
    assert attrs["software"].splitlines() == [
        *expected_stack(), f"python {python}, numpy {np.__version__}, numba {numba.__version__}",
        "writer (1 rank): serial HDF5"]


@pytest.mark.parametrize("sections,key", [
    ({"model": {"N": 60, "bb": 1.0}}, "model.bb"),
    ({"model": {"N": 0}}, "model.N"),
    ({"model": {"N": 60, "nu": -1e-8}}, "model.nu"),
    ({"model": {"N": 60, "b": "big"}}, "model.b"),
    ({"run": {"events": 0}}, "run.events"),
    ({"integrator": {"method": "euler"}}, "integrator.method"),
    ({"integrator": {"dt": 2.0}}, "integrator.dt"),
    ({"sweep": {"q": [1, 2]}}, "sweep.q"),
    ({"sweep": {"b": []}}, "sweep.b"),
    ({"extra": {"x": 1}}, "[extra]"),
])
def test_bad_config_gives_one_line_error_naming_the_key(tmp_path, sections, key):
    cfg = write_config(tmp_path / "bad.toml", **sections)
    res = run_cli("run", cfg)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and key in lines[0] and lines[0].startswith("error:")
    assert not (tmp_path / "bad.h5").exists()


def test_bad_override_and_missing_file(tmp_path):
    cfg = write_config(tmp_path / "c.toml")
    res = run_cli("validate", cfg, "--set", "model.l=0")
    assert res.returncode == 2 and "model.l" in res.stderr
    res = run_cli("validate", tmp_path / "nope.toml")
    assert res.returncode == 2 and "nope.toml" in res.stderr


def test_unstable_step_stops_with_task_and_event_and_keeps_old_catalog(small_run, tmp_path):
    """dt beyond the RK4 stability limit: a clear error naming task and event, nothing overwritten."""
    d, cfg = small_run
    before = (d / "cfg.h5").read_bytes()
    res = run_cli("run", cfg, "--force", "--set", "integrator.method=rk4", "--set", "integrator.dt=0.02")
    assert res.returncode == 1
    line = res.stderr.strip().splitlines()[0]
    assert "task 0" in line and "event" in line and "stability" in line
    assert (d / "cfg.h5").read_bytes() == before
