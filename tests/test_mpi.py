"""The runner under real `mpiexec`: rank-count invariance, writers, resume, failures.

Every job runs under a timeout that kills mpiexec and its ranks (tests/processes.py); waits are
on conditions (a committed batch), not on sleeps.
"""
import os
import shutil
import signal
import sys

import numpy as np
import pytest

from ensemble import cli
from ensemble.store import reader, schema
from ensemble.store.files import partial_path

from .conftest import committed, run_cli, write_config
from .processes import ROOT, Started, child_env, descendants, ensemble_here, run_bounded, wait_for
from .same_catalogs import assert_same_events

pytestmark = pytest.mark.mpi
MPIEXEC = shutil.which("mpiexec")
if MPIEXEC is None:
    pytest.skip("mpiexec not found (make setup installs MPICH)", allow_module_level=True)
TIMEOUT = 120     # seconds for a wait or a short job


def mpi_cmd(n, *args):
    return [MPIEXEC, "-n", str(n), sys.executable, "-m", "ensemble", *map(str, args)]


def mpirun(n, *args, timeout=300):
    # a hung job fails the test (showing its output) instead of hanging the suite
    return run_bounded(mpi_cmd(n, *args), timeout, env=child_env())


def injected_cmd(n, setup, *argv):
    """mpiexec -n n running `python -m ensemble argv` after `setup` (code using tests.inject)."""
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; {setup}; "
            f"inject.main({list(map(str, argv))!r})")
    return [MPIEXEC, "-n", str(n), sys.executable, "-c", code]


@pytest.fixture(scope="module")
def two_tasks(tmp_path_factory):
    """Two tasks (b = 20 and 30): fewer tasks than ranks with -n 3. Serial reference run.
    (60 events each, committed in batches of 20: each task's rows reach the writer in several parts.)"""
    d = tmp_path_factory.mktemp("mpi2")
    cfg = write_config(d / "cfg.toml", sweep={"b": [20.0, 30.0]}, run={"seeds": 1, "events": 60, "transient": 20},
                       output={"batch": 20, "flush_seconds": 0.5})
    res = ensemble_here("run", cfg, "-o", d / "serial.h5")     # (in this process: one rank, no mpiexec)
    assert res.returncode == 0, res.stderr
    return d, cfg


MPIO = pytest.mark.parallel_hdf5
WRITER_LABELS = {"parallel": "parallel HDF5 (mpio), independent writes",
                 "rank0": "serial HDF5 on rank 0, rows sent by message"}


# Three ranks for two tasks: each writer with a rank that has no task (it must still take part in the
# parallel writer's collective calls; the rank-0 writer must still hear its "done"). Each writer with two
# ranks, each busy, is the run of the signal tests below (auto: parallel on the parallel stack; rank0).
@pytest.mark.parametrize("ranks,writer", [(1, "auto"), pytest.param(3, "parallel", marks=MPIO), (3, "rank0")])
def test_catalog_independent_of_ranks_and_writer(two_tasks, ranks, writer):
    d, cfg = two_tasks
    out = d / f"n{ranks}_{writer}.h5"
    res = mpirun(ranks, "run", cfg, "-o", out, "--set", f'output.writer="{writer}"')
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "serial.h5", out)
    _, tasks, attrs = reader.read(out)
    assert set(tasks["rank"]) <= set(range(ranks)) and np.all(tasks["rank"] >= 0)
    assert np.all(tasks["events_per_second"] > 0)
    # each records the writer that made it (assert_same_events compares events and task rows only)
    used = WRITER_LABELS[writer] if ranks > 1 else "serial HDF5"
    assert attrs["software"].splitlines()[-1] == f"writer ({ranks} rank{'s' if ranks > 1 else ''}): {used}"


EVENTS = 120       # per task of four_tasks


@pytest.fixture(scope="module")
def four_tasks(tmp_path_factory):
    """Four tasks long enough (~2.5 s on 2 ranks) to be interrupted. Serial reference run."""
    d = tmp_path_factory.mktemp("mpi4")
    cfg = write_config(d / "cfg.toml", sweep={"b": [20.0, 30.0]},
                       run={"seeds": 2, "events": EVENTS, "transient": 30},
                       output={"batch": 20, "flush_seconds": 0.25, "progress_seconds": 0.5})
    res = ensemble_here("run", cfg, "-o", d / "full.h5")
    assert res.returncode == 0, res.stderr
    return d, cfg


def resume_equals_uninterrupted(d, cfg, out):
    res = mpirun(2, "run", cfg, "-o", out, "--resume")
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "full.h5", out)
    return res


def rank_pids(root):
    """PIDs of the ranks started by mpiexec `root` (hydra puts each in its own session)."""
    found = []
    for pid in descendants(root):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                args = fh.read().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if "-m ensemble run" in args and "hydra" not in args and "mpiexec" not in args:
            found.append(pid)
    return sorted(found)


def start_and_interrupt(cfg, out, how, writer="auto"):
    """Start a 2-rank run, wait for a committed batch, interrupt it; returns (exit code, output).

    The run computes for ~2.5 s on 2 ranks (~240 events/s in all, measured); the first batch is
    committed after ~1/6 of it (the 30 events of a task's transient and 20 more), and the signals
    follow within milliseconds (polling every 50 ms).
    """
    with Started(mpi_cmd(2, "run", cfg, "-o", out, "--set", f'output.writer="{writer}"'), env=child_env()) as proc:
        wait_for(lambda: committed(out), TIMEOUT, "a committed batch", proc)
        ranks = rank_pids(proc.pid)
        assert len(ranks) == 2, ranks
        if how == "kill":
            for pid in ranks + [proc.pid]:
                os.kill(pid, signal.SIGKILL)
        else:
            # Signal the ranks themselves, as Slurm does (hydra's mpiexec, when signalled, forwards
            # the signal but then exits 0 whatever the ranks return). `one`/`other`: only the
            # first/second rank by pid (rank order unknown), `all`: both.
            sig, which = how
            for pid in {"one": ranks[:1], "other": ranks[1:], "all": ranks}[which]:
                os.kill(pid, sig)
        return proc.wait(TIMEOUT, f"the run after {how}"), proc.output


# (marked slow: the same paths again with another signal or rank; `make test-all` runs them, CI's `make test`
# the three that take every path: both ranks, one rank, and the rank-0 writer with the other rank signalled)
SLOW = pytest.mark.slow


@pytest.mark.parametrize("sig,which,writer", [
    (signal.SIGTERM, "all", "auto"), (signal.SIGUSR1, "one", "auto"),
    pytest.param(signal.SIGINT, "all", "auto", marks=SLOW),
    # the rank-0 writer: rank 0 must serve the other rank's last rows and its "done", wherever they arrive
    pytest.param(signal.SIGTERM, "one", "rank0", marks=SLOW), (signal.SIGTERM, "other", "rank0"),
    pytest.param(signal.SIGTERM, "all", "rank0", marks=SLOW),
    pytest.param(signal.SIGUSR1, "other", "rank0", marks=SLOW)])
def test_resume_after_signal_equals_uninterrupted(four_tasks, sig, which, writer, capsys):
    """Every rank checkpoints and exits 75 (also when only one rank got the signal); resume completes."""
    d, cfg = four_tasks
    out = d / f"sig{int(sig)}_{which}_{writer}.h5"
    code, log = start_and_interrupt(cfg, out, (sig, which), writer)
    assert code == 75, log
    assert "interrupted" in log and not out.exists()
    _, tasks, _ = reader.read(partial_path(out))
    assert 0 < tasks["events_written"].sum() < 4 * EVENTS      # really cut in the middle
    assert cli.main(["status", str(out)]) == 0     # (`python -m ensemble status`, in this process)
    status = capsys.readouterr().out
    assert "interrupted" in status and "resume" in status
    resume_equals_uninterrupted(d, cfg, out)


def test_resume_after_kill9_loses_and_duplicates_nothing(four_tasks):
    d, cfg = four_tasks
    out = d / "killed.h5"
    code, log = start_and_interrupt(cfg, out, "kill")
    assert code != 0 and not out.exists()
    events, tasks, _ = reader.read(partial_path(out))   # readable after kill -9
    assert len(events["t"]) == tasks["events_written"].sum() < 4 * EVENTS
    assert os.path.exists(str(out) + ".lock")          # left behind by the dead run ...
    res = resume_equals_uninterrupted(d, cfg, out)
    assert "took over the lock left by a run that died" in res.stdout    # ... and recognised


def test_resume_refuses_a_different_config(four_tasks):
    d, cfg = four_tasks
    out = d / "other.h5"
    code, _ = start_and_interrupt(cfg, out, (signal.SIGTERM, "all"))
    assert code == 75
    res = run_cli("run", cfg, "-o", out, "--resume", "--set", "model.a=1.0")
    assert res.returncode == 2 and "model.a" in res.stderr and "resume" in res.stderr
    res = run_cli("run", cfg, "-o", out)
    assert res.returncode == 2 and "--resume" in res.stderr


def test_a_genuine_error_on_one_rank_aborts_the_job(tmp_path):
    """A bug (not a numerical failure) on rank 1 takes every rank down at once; what was committed stays."""
    cfg = write_config(tmp_path / "cfg.toml", sweep={"b": [20.0, 30.0]},
                       run={"seeds": 2, "events": 200000, "transient": 10},
                       output={"batch": 20, "flush_seconds": 0.2})
    # rank 1 fails at its 4th kernel call (~1 s in, some batches committed); task 0 alone would run for
    # half an hour more (~120 events/s a rank): a rank left running, or a hang, fails at the deadline
    res = run_bounded(injected_cmd(2, "inject.fail_on_rank(1, after_calls=3)", "run", cfg, "-o", tmp_path / "x.h5"),
                      TIMEOUT, env=child_env())
    assert res.returncode != 0
    assert "rank 1" in res.stderr and "injected failure" in res.stderr
    reader.read(partial_path(tmp_path / "x.h5"))   # what was committed stays readable


def test_a_failing_task_does_not_stop_the_others_under_mpi(tmp_path):
    """Task 1 (b = 80) is unstable with rk4 at dt = 1e-3: recorded as failed; the rest finish; exit 1.
    A resume with the aging law's own method (exp4, adaptive) reruns it."""
    cfg = write_config(tmp_path / "cfg.toml", sweep={"b": [20.0, 80.0, 30.0]},
                       run={"seeds": 1, "events": 40, "transient": 10}, integrator={"method": "rk4", "dt": 1e-3},
                       output={"batch": 20, "flush_seconds": 0.5})
    out = tmp_path / "x.h5"
    res = mpirun(2, "run", cfg, "-o", out, timeout=TIMEOUT)
    assert res.returncode == 1, res.stderr
    assert "task 1" in res.stderr and "stability" in res.stderr
    _, tasks, _ = reader.read(partial_path(out))
    assert list(tasks["status"]) == [schema.FINISHED, schema.FAILED, schema.FINISHED]
    res = mpirun(2, "resume", out, "--set", 'integrator.method="exp4"', timeout=TIMEOUT)
    assert res.returncode == 0, res.stderr
    _, tasks, _ = reader.read(out)
    assert list(tasks["events_written"]) == [40] * 3
    assert [text.splitlines()[0] for text in tasks["integrator"]] == ['method = "rk4"', 'method = "exp4"',
                                                                      'method = "rk4"']


def test_a_second_run_cannot_open_a_live_parallel_catalog(two_tasks, tmp_path):
    """Two mpio runs on one output: the second is refused, the first ends with the right catalog.

    The first is held at its first kernel call (lock taken, catalog open) until the second has
    been refused: it is live then, however fast it would have finished.
    """
    d, cfg = two_tasks
    out = tmp_path / "two.h5"
    ready, go = tmp_path / "held", tmp_path / "go"
    with Started(injected_cmd(2, f"inject.hold({str(ready)!r}, {str(go)!r})", "run", cfg, "-o", out),
                 env=child_env()) as first:
        wait_for(ready.exists, TIMEOUT, "the first run held", first)
        second = mpirun(2, "run", cfg, "-o", out, "--force", "--set", "model.b=30", timeout=TIMEOUT)
        assert second.returncode == 2 and "in use by another run" in second.stderr, second.stderr
        go.touch()
        code = first.wait(300, "the first run")
    assert code == 0, first.output
    assert_same_events(d / "serial.h5", out)
