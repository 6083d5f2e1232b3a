"""Faults, serially: crashes at every write of a batch, corrupt files, concurrent runs, stale locks,
a full disk, bad output paths, late signals, and what `status` says in each case.

Every command runs under a timeout (tests/processes.py), waits are on conditions (a committed
batch, a progress line), not on sleeps of a guessed length, and an interruption that must come
before the run ends is injected at a known point (tests/inject.py), not sent at a guessed time.
"""
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from ensemble.run import lock
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.store.files import partial_path
from ensemble.store.integrity import commit_crc

from .conftest import committed, write_config
from . import inject
from .inject import CRASH_CODE
from .processes import ROOT, Started, child_env, ensemble_here as here, run_bounded, wait_for

TIMEOUT = 120     # seconds for any one command or wait: what they take is a few


def injected(setup, *argv, timeout=TIMEOUT):
    """Run `python -m ensemble argv` in a subprocess after `setup` (code using tests.inject)."""
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; {setup}; "
            f"inject.main({list(map(str, argv))!r})")
    return run_bounded([sys.executable, "-c", code], timeout, env=child_env())


def cli(*args, timeout=TIMEOUT):
    """`python -m ensemble args` in a process of its own: for damaged catalogs and full disks, where HDF5 may
    crash at exit and the run leaves at once (os._exit); the others run in this process (`here`)."""
    return run_bounded([sys.executable, "-m", "ensemble", *args], timeout, env=child_env())


def same_events(path_a, path_b):
    a, ta, _ = reader.read(path_a)
    b, tb, _ = reader.read(path_b)
    assert len(a["t"]) == len(b["t"]) > 0
    for name in schema.EVENT_FIELDS:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    np.testing.assert_array_equal(ta["events_written"], tb["events_written"])


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """Two tasks of three batches each, and the uninterrupted catalog (full.h5), whose run logs its
    writes and flushes to writes.log (tests.inject.log_writes)."""
    d = tmp_path_factory.mktemp("faults")
    cfg = write_config(d / "cfg.toml", run={"seeds": 2, "events": 60, "transient": 10},
                       output={"batch": 20, "flush_seconds": 1000.0})
    res = injected(f"inject.log_writes({str(d / 'writes.log')!r})", "run", cfg, "-o", d / "full.h5")
    assert res.returncode == 0, res.stderr
    return d, cfg


@pytest.mark.slow    # (nine crashed runs and their resumes, 18 s: the slower tier, run by CI; make test keeps the
#                      crash before a finish, the `crashed` fixture's, and tests/test_mpi.py's kill -9)
def test_crash_at_each_kind_of_write_of_a_batch_resumes_to_the_uninterrupted_catalog(small):
    """kill -9 before each kind of write and each flush of task 0's second batch, and just after it.

    The batch writes its event columns one after another (one loop), then flushes, writes the checkpoint
    state, flushes, writes the commit row and events_written, and flushes. The crashes come before its
    last event column (the others written), before every write and flush after that, and before the
    first column of the next batch (none of that batch's written yet)."""
    d, cfg = small
    log = (d / "writes.log").read_text().splitlines()
    writes = {int(k): what for k, what in (line.split(" ", 1) for line in log)}
    starts = [k for k, what in writes.items() if what == "write /events/task"]
    # task 0's second batch: from its first event column to the first write of the next batch
    batch = range(starts[1], starts[2])
    columns = [k for k in batch if writes[k].startswith("write /events/")]
    assert len(columns) == len(schema.EVENT_FIELDS) and columns == list(range(starts[1], columns[-1] + 1))
    crashes = [columns[-1], *(k for k in batch if k > columns[-1]), starts[2]]
    kinds = [writes[k] for k in crashes]
    assert {"write /checkpoint/state", "write /checkpoint/commit", "write /tasks/events_written"} <= set(kinds)
    assert kinds.count("flush") >= 3, kinds
    for k in crashes:
        out = d / f"crash{k}.h5"
        res = injected(f"inject.crash_at_write({k})", "run", cfg, "-o", out)
        assert res.returncode == CRASH_CODE, res.stderr
        events, tasks, _ = reader.read(partial_path(out))       # consistent after the crash
        assert len(events["t"]) == tasks["events_written"].sum() < 120
        res = here("run", cfg, "-o", out, "--resume")
        assert res.returncode == 0, (k, res.stderr)
        same_events(d / "full.h5", out)


def _flip_byte(path, dataset, index):
    """Flip one byte of element `index` of a contiguous dataset, in the file's bytes."""
    with h5py.File(path, "r") as h5:
        ds = h5[dataset]
        offset = ds.id.get_offset() + index * ds.dtype.itemsize
    with open(path, "r+b") as fh:
        fh.seek(offset + 3)
        byte = fh.read(1)
        fh.seek(offset + 3)
        fh.write(bytes([byte[0] ^ 0x10]))


@pytest.fixture(scope="module")
def crashed(small):
    """A catalog crashed (kill -9) just before the last write before its first finish record (inject.before_finish):
    task 0 has committed its 60 events, its finish is not recorded; a .partial to resume, and the lock the dead
    run left."""
    d, cfg = small
    out = d / "crashed.h5"
    res = injected(f"inject.crash_at_write({inject.before_finish(d / 'writes.log')})", "run", cfg, "-o", out)
    assert res.returncode == CRASH_CODE, res.stderr
    _, tasks, _ = reader.read(partial_path(out))
    assert list(tasks["events_written"]) == [60, 0] and tasks["status"][0] == schema.OPEN
    return cfg, out


@pytest.fixture
def interrupted(crashed, tmp_path):
    """A copy of the crashed catalog (its .partial and its lock), for one test to damage or resume."""
    cfg, crashed_out = crashed
    out = tmp_path / "x.h5"
    shutil.copyfile(partial_path(crashed_out), partial_path(out))
    if os.path.exists(lock.lock_path(crashed_out)):
        shutil.copyfile(lock.lock_path(crashed_out), lock.lock_path(out))
    return cfg, out


@pytest.mark.parametrize("where,message", [
    ("state", "checkpoint slot"), ("event", "fail their checksum"), ("commit", "commit row")])
def test_a_one_byte_flip_fails_resume_and_read_naming_the_task(interrupted, where, message):
    cfg, out = interrupted
    partial = partial_path(out)
    with h5py.File(partial, "r") as h5:
        row = h5["checkpoint/commit"][0]
        slot = int(np.argmax(row[:, 0]))          # the slot in use: highest sequence number
        n = int(h5["tasks/N"][0])
    if where == "state":
        _flip_byte(partial, "checkpoint/state", slot * (4 * n + 2) + 5)
    elif where == "event":
        _flip_byte(partial, "events/mu", 7)
    else:
        _flip_byte(partial, "checkpoint/commit", slot * schema.NCOMMIT + schema.C_DONE)
    res = cli("run", cfg, "-o", out, "--resume")
    assert res.returncode != 0 and "task 0" in res.stderr and message in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    if where != "state":        # readers do not read checkpoints
        with pytest.raises(CatalogError, match=f"task 0.*{message}"):
            reader.read(partial)


def test_an_out_of_range_commit_row_with_a_valid_checksum_is_refused(interrupted):
    """A negative event count (once an endless loop) with a matching CRC: the range check catches it."""
    cfg, out = interrupted
    partial = partial_path(out)
    with h5py.File(partial, "r+") as h5:
        rows = h5["checkpoint/commit"][0]
        slot = int(np.argmax(rows[:, 0]))
        fields = [int(x) for x in rows[slot][:schema.C_ROW_CRC]]
        fields[schema.C_DONE] = -5
        h5["checkpoint/commit"][0, slot] = fields + [commit_crc(0, slot, fields)]
    res = cli("run", cfg, "-o", out, "--resume")
    assert res.returncode == 1 and "task 0" in res.stderr and "out of range" in res.stderr


def start(cfg, out, *extra, **kwargs):
    """`run` in the background (a Started: use it in a `with` block)."""
    return Started([sys.executable, "-m", "ensemble", "run", cfg, "-o", out, *extra], env=child_env(), **kwargs)


@pytest.fixture(scope="module")
def long_cfg(tmp_path_factory):
    d = tmp_path_factory.mktemp("long")
    return write_config(d / "long.toml", run={"seeds": 2, "events": 200000, "transient": 10},
                        output={"batch": 20, "flush_seconds": 0.2, "progress_seconds": 1000.0})


def stop(proc):
    """SIGTERM to a started run; (exit code, output) once it has ended."""
    proc.send_signal(signal.SIGTERM)
    return proc.wait(TIMEOUT, "the run after SIGTERM"), proc.output


def test_a_second_run_on_a_live_output_is_refused_and_the_first_one_is_intact(long_cfg, tmp_path):
    out = tmp_path / "live.h5"
    with start(long_cfg, out) as first:        # 200000 events: live until stopped
        wait_for(lambda: committed(out), TIMEOUT, "a committed batch", first)
        for extra in (["--force"], ["--resume"], []):
            res = here("run", long_cfg, "-o", out, *extra)
            assert res.returncode == 2 and "in use by another run" in res.stderr, res.stderr
            assert f"pid {first.pid}" in res.stderr
        status = here("status", out)
        assert status.returncode == 0 and "running" in status.stdout and "progress:" in status.stdout
        code, log = stop(first)
    assert code == 75, log
    assert not os.path.exists(lock.lock_path(out))          # released on the way out
    events, tasks, _ = reader.read(partial_path(out))
    assert len(events["t"]) == tasks["events_written"].sum() > 0


def test_status_shows_progress_within_seconds_of_the_start(long_cfg, tmp_path):
    """Before any flush (flush_seconds = 1000 here) the lock carries the live progress line."""
    out = tmp_path / "early.h5"
    with start(long_cfg, out, "--set", "output.flush_seconds=1000") as proc:
        # a rate: events done ("starting" and "events 0/..." come before any)
        wait_for(lambda: "events/s" in lock.read_info(out).get("progress", ""), TIMEOUT,
                 "a progress line in the lock", proc)
        status = here("status", out)
        assert "running" in status.stdout and "events/s" in status.stdout, status.stdout
        assert "open" in status.stdout         # per task, from the catalog being written
        code, log = stop(proc)
    assert code == 75, log


def test_a_stale_lock_of_a_dead_run_is_taken_over(small, tmp_path):
    d, cfg = small
    out = tmp_path / "stale.h5"
    dead = subprocess.Popen(["true"])
    dead.wait(timeout=TIMEOUT)
    with open(lock.lock_path(out), "w") as fh:
        fh.write(f"host: {socket.gethostname()}\npid: {dead.pid}\nstarted: x\nheartbeat: {time.time():.1f}\n")
    res = here("run", cfg, "-o", out)
    assert res.returncode == 0, res.stderr
    assert "took over the lock left by a run that died" in res.stdout
    assert not os.path.exists(lock.lock_path(out))


def test_a_lock_from_another_host_with_a_fresh_heartbeat_is_refused_with_how_to_remove_it(small, tmp_path):
    d, cfg = small
    out = tmp_path / "foreign.h5"
    path = lock.lock_path(out)
    # an hour ahead (that host's clock may be): fresh however long the run below takes to start,
    # where `now` would turn stale after lock.STALE_SECONDS
    with open(path, "w") as fh:
        fh.write(f"host: node-elsewhere\npid: 4242\nstarted: x\nheartbeat: {time.time() + 3600:.1f}\n")
    res = here("run", cfg, "-o", out)
    assert res.returncode == 2 and "node-elsewhere" in res.stderr and f"rm {path}" in res.stderr
    assert not os.path.exists(partial_path(out))
    os.remove(path)
    assert here("run", cfg, "-o", out).returncode == 0


def test_resume_of_a_finished_catalog_refuses_a_changed_config(small):
    d, cfg = small
    res = here("run", cfg, "-o", d / "full.h5", "--resume", "--set", "model.b=30")
    assert res.returncode == 2 and "model.b" in res.stderr
    res = here("run", cfg, "-o", d / "full.h5", "--resume")
    assert res.returncode == 0 and "complete" in res.stdout


def test_output_paths_are_checked_before_any_work(small, tmp_path):
    d, cfg = small
    (tmp_path / "adir").mkdir()
    for target in (tmp_path / "adir", tmp_path / "missing" / "x.h5"):
        res = here("run", cfg, "-o", target, "--force")
        assert res.returncode == 2 and str(target.parent if "missing" in str(target) else target) in res.stderr
        assert "progress" not in res.stdout and not os.path.exists(partial_path(target))
    assert list((tmp_path / "adir").iterdir()) == []


def test_a_signal_just_after_the_rename_leaves_exit_0(small, tmp_path):
    d, cfg = small
    res = injected("inject.signal_after_rename(15)", "run", cfg, "-o", tmp_path / "late.h5")
    assert res.returncode == 0, res.stderr      # not 143: the catalog is complete
    same_events(d / "full.h5", tmp_path / "late.h5")


def test_resume_continues_from_the_stored_config_without_retyping_overrides(long_cfg, tmp_path):
    """A run started with --set options, interrupted, is continued by `resume CATALOG` alone."""
    sets = ["--set", "run.events=60", "--set", "model.b=30", "--set", "integrator.dt=5e-4",
            "--set", "output.flush_seconds=0.2"]
    ref = tmp_path / "ref.h5"
    assert here("run", long_cfg, "-o", ref, *sets).returncode == 0
    out = tmp_path / "cut.h5"
    # SIGTERM at the first batch of events: it is committed, the rest of the run is not done
    res = injected("inject.signal_at_write(15)", "run", long_cfg, "-o", out, *sets)
    assert res.returncode == 75, res.stdout + res.stderr
    _, tasks, _ = reader.read(partial_path(out))
    assert 0 < tasks["events_written"].sum() < 120
    res = here("resume", out)
    assert res.returncode == 0, res.stderr
    same_events(ref, out)
    res = here("resume", out)
    assert res.returncode == 0 and "complete" in res.stdout


def test_resume_refuses_changes_to_the_physics_and_integrator_changes_without_failed_tasks(interrupted):
    cfg, out = interrupted
    res = here("resume", out, "--set", "model.b=30")
    assert res.returncode == 2 and "model.b" in res.stderr and "new run" in res.stderr
    res = here("resume", out, "--set", "integrator.dt=1e-4")
    assert res.returncode == 2 and "no failed task" in res.stderr


def test_a_failing_task_is_recorded_and_rerun_with_another_integrator(tmp_path):
    """b = 80 is unstable for rk4 at dt = 1e-3: the task fails, the other finishes; resume reruns it with
    exp4 (the aging law's exponential method), and the rerun task is what exp4 gives from the start."""
    cfg = write_config(tmp_path / "mix.toml", sweep={"b": [20.0, 80.0]}, run={"seeds": 1, "events": 30,
                       "transient": 10}, integrator={"method": "rk4", "dt": 1e-3}, output={"batch": 10})
    out = tmp_path / "mix.h5"
    res = here("run", cfg, "-o", out)
    assert res.returncode == 1 and "task 1" in res.stderr and "stability" in res.stderr
    assert "resume" in res.stdout and not out.exists()
    _, tasks, _ = reader.read(partial_path(out))
    assert list(tasks["status"]) == [schema.FINISHED, schema.FAILED] and "stability" in tasks["error"][1]
    status = here("status", out)
    assert status.returncode == 0 and "failed: tasks 1" in status.stdout
    assert here("resume", out).returncode == 1           # nothing changed: still failed, said again
    exp4 = ["--set", 'integrator.method="exp4"']
    res = here("resume", out, *exp4)
    assert res.returncode == 0, res.stderr
    events, tasks, _ = reader.read(out)
    assert list(tasks["status"]) == [schema.FINISHED] * 2 and list(tasks["events_written"]) == [30, 30]
    assert 'method = "rk4"' in tasks["integrator"][0] and 'method = "exp4"' in tasks["integrator"][1]
    ref = tmp_path / "ref.h5"
    assert here("run", cfg, "-o", ref, *exp4).returncode == 0
    ref_events, _, _ = reader.read(ref)
    for name in schema.EVENT_FIELDS:       # the rerun task equals a run with exp4 from the start
        np.testing.assert_array_equal(events[name][events["task"] == 1], ref_events[name][ref_events["task"] == 1])


@pytest.fixture
def small_disk(tmp_path):
    """A tmpfs of 80 KiB (needs root, as in CI; elsewhere the test cannot make a full disk)."""
    mount = tmp_path / "disk"
    mount.mkdir()
    res = run_bounded(["mount", "-t", "tmpfs", "-o", "size=80k", "tmpfs", mount], TIMEOUT)
    if res.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here ({res.stderr.strip()})")
    yield mount
    run_bounded(["umount", "-l", mount], TIMEOUT)


def test_a_full_disk_stops_the_run_with_one_line_and_nothing_lost(small, small_disk):
    d, cfg = small
    # 1000 events: a catalog of 110 KiB (about 50 KiB of it written when it is created, the rest sparse
    # until the events come), more than the disk holds
    big = ["--set", "run.events=500", "--set", "output.batch=50"]
    # at creation: the space is reserved up front, so the run stops before any work
    res = cli("run", cfg, "-o", small_disk / "a.h5", *big)
    assert res.returncode == 1 and "No space left on device" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and not any(small_disk.iterdir())
    # in the middle (a file system without fallocate, whose space another process takes while the run
    # goes on: nothing reserved, the check before creation passed): one line, a readable catalog
    res = injected("from ensemble import space; from ensemble.store import files; "
                   "files.reserve_space = lambda path: None; space.check_fits = lambda path, nbytes: None",
                   "run", cfg, "-o", small_disk / "b.h5", *big)
    assert res.returncode == 1 and "No space left on device" in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    status = cli("status", small_disk / "b.h5")
    assert status.returncode == 0 and "interrupted" in status.stdout
    # space freed: the same catalog, resumed, completes
    assert run_bounded(["mount", "-o", "remount,size=8m", small_disk], TIMEOUT).returncode == 0
    res = cli("resume", small_disk / "b.h5")
    assert res.returncode == 0, res.stderr
    events, tasks, _ = reader.read(small_disk / "b.h5")
    assert len(events["t"]) == tasks["events_written"].sum() == 1000


@pytest.mark.slow
def test_signal_during_kernel_compilation_is_acknowledged_at_once(small, tmp_path):
    """An empty numba cache: rank 0 says it compiles; SIGINT is acknowledged within seconds, exit 75.
    Slow by nature (the slower tier, `make slow`): it needs a real compilation, about a minute and a half."""
    d, cfg = small
    with Started([sys.executable, "-m", "ensemble", "run", cfg, "-o", tmp_path / "c.h5"],
                 env=child_env(NUMBA_CACHE_DIR=str(tmp_path / "cache"))) as proc:
        wait_for(lambda: len(proc.lines) >= 4, TIMEOUT, "four lines of output", proc)
        assert proc.lines[3].startswith("compiling kernels"), proc.lines   # after mpi, hdf5, "writing ..."
        proc.send_signal(signal.SIGINT)
        code, out = proc.wait(300, "the run after SIGINT while compiling"), proc.output
    assert code == 75, out
    # acknowledged while compiling: before the kernels were ready, not after
    assert "SIGINT received while compiling kernels" in out.split("kernels ready")[0], out
    assert "interrupted (SIGINT)" in out
    assert "progress" not in out.split("kernels ready")[0]    # the rate does not count the compilation
    shutil.rmtree(tmp_path / "cache", ignore_errors=True)


def test_kernel_calls_paused_in_the_middle_of_events_give_the_same_catalog(small, tmp_path):
    """Kernel calls of 1000 block-steps (worker.MIN_BUDGET) from a task's first call on, and
    poll_seconds so short (1e-5) that they stay at that budget on any machine: calls end inside an event more
    often than there are events (the run counts them), and the catalog is the one of `small`, whose calls (of
    250k block-steps at first) end between events. (At poll_seconds = 1e-3 the budget grew to a millisecond's
    work, and on a fast machine the pauses fell below the bound: 117 on 2026-12-04.)"""
    d, cfg = small
    fast = ["--set", "run.poll_seconds=1e-5"]
    out = tmp_path / "paused.h5"
    count = tmp_path / "pauses.txt"
    res = injected(f"inject.count_pauses({str(count)!r}, first_budget=1000)", "run", cfg, "-o", out, *fast)
    assert res.returncode == 0, res.stderr
    assert int(count.read_text()) > 140        # more pauses than the 2 x (60 + 10) events
    same_events(d / "full.h5", out)
    # and a checkpoint taken while an event is paused resumes to the same catalog (SIGTERM comes
    # when a kernel call first ends inside an event; the stop request is served right after it)
    cut = tmp_path / "cut.h5"
    res = injected("from ensemble.run import worker; worker.FIRST_BUDGET = 1000; inject.signal_when_paused(15)",
                   "run", cfg, "-o", cut, *fast)
    assert res.returncode == 75, res.stdout + res.stderr
    assert here("resume", cut).returncode == 0
    same_events(d / "full.h5", cut)


def test_a_signal_during_one_very_long_event_is_served_within_a_kernel_call(tmp_path):
    """One event takes minutes here (RK4 at dt = 1e-8); SIGTERM still ends the run at once with 75."""
    cfg = write_config(tmp_path / "slow.toml", model={"N": 200, "b": 20.0},
                       run={"seeds": 1, "events": 10, "transient": 0}, integrator={"method": "rk4", "dt": 1e-8})
    out = tmp_path / "slow.h5"
    with start(cfg, out) as proc:
        # the work loop has started (it refreshes the lock's progress line between kernel calls)
        wait_for(lambda: lock.read_info(out).get("progress", "starting") != "starting", TIMEOUT,
                 "the work loop", proc)
        code, log = stop(proc)
    assert code == 75, log
    _, tasks, _ = reader.read(partial_path(out))
    assert tasks["events_written"][0] == 0 and tasks["events_done"][0] == 0   # the event was in progress


def test_status_of_the_partial_name_and_of_a_damaged_catalog(interrupted, tmp_path):
    cfg, out = interrupted
    res = here("status", partial_path(out))          # the .partial's own name: not "complete"
    assert res.returncode == 0 and "interrupted" in res.stdout.splitlines()[0]
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(open(partial_path(out), "rb").read()[:4096])
    res = cli("status", damaged)
    assert res.returncode == 1 and "damaged.h5" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_a_closed_stdout_does_not_stop_the_run(small, tmp_path):
    """`run ... | head -1`: the log's reader goes away, the run goes on to a complete catalog."""
    d, cfg = small
    # the reader closes stdout after the first line, as head does
    with start(cfg, tmp_path / "p.h5", "--set", "output.progress_seconds=0.01", separate_stderr=True,
               stdout_lines=1) as proc:
        code = proc.wait(TIMEOUT)
    assert code == 0, proc.errors
    same_events(d / "full.h5", tmp_path / "p.h5")


def test_status_names_what_a_wrong_file_is(small, tmp_path):
    """A config or a directory given to `status`: one line naming the file and what it is."""
    d, cfg = small
    (tmp_path / "adir.h5").mkdir()
    for path, words in ((cfg, "TOML"), (tmp_path / "adir.h5", "directory")):
        res = here("status", path)
        assert res.returncode == 1 and str(path) in res.stderr and words in res.stderr, res.stderr
        assert len(res.stderr.strip().splitlines()) == 1


def test_a_rank_long_without_a_row_says_where_its_chain_is(tmp_path, monkeypatch):
    """A task that makes no row for QUIET_SECONDS (a long event, a long creep episode) gets a line saying where its
    chain is, then again after four times as long: no run goes quiet without saying why (N = 5, a = 100, b = 18
    once sat minutes at one row with nothing said). Here the wait is shrunk to nothing and the kernel calls to a
    few block-steps, so that calls end inside an event and inside a creep phase."""
    from ensemble.run import worker
    monkeypatch.setattr(worker, "QUIET_SECONDS", 1e-9)
    monkeypatch.setattr(worker, "FIRST_BUDGET", 1)
    monkeypatch.setattr(worker, "MIN_BUDGET", 1)
    for model, words in (({"N": 60, "b": 20.0}, ": an event in progress, "),
                         ({"N": 40, "b": 15.0}, " blocks creeping at model time ")):
        cfg = write_config(tmp_path / f"quiet{model['b']:g}.toml", model=model,
                           run={"events": 5, "transient": 0, "seeds": 1, "poll_seconds": 1e-6})
        res = here("run", cfg, "-o", tmp_path / f"quiet{model['b']:g}.h5")
        assert res.returncode == 0, res.stderr
        notes = [line for line in res.stdout.splitlines() if line.startswith("note: rank 0: task 0: no row for ")]
        assert any(words in line for line in notes), res.stdout[-3000:]
