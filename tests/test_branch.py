"""Branching (run.branch): each point spun up once, its seeds started from that state, perturbed.

What must hold: an unperturbed branch continues the spun-up trajectory exactly; the catalog says
which tasks branched from which spin-up; the result does not depend on the number of ranks or the
writer; an interruption anywhere (during a spin-up, while waiting for the other spin-ups, while
branching) resumes to the uninterrupted catalog; a failed spin-up fails its point's tasks, which a
rerun with another integrator completes.
"""
import re
import shutil
import signal
import sys

import h5py
import numpy as np
import pytest

from ensemble import cli
from ensemble.store import reader, schema
from ensemble.store.files import partial_path
from ensemble.config import DECORRELATION_PER_BLOCK, ConfigError, loads

from . import inject
from .conftest import write_config
from .processes import ROOT, child_env, ensemble_here, run_bounded
from .same_catalogs import assert_same_events
from .test_export import assert_described, descriptions

TIMEOUT = 180
SEEDS, EVENTS, SPINUP, DECORRELATE = 3, 40, 45, 15
MPIEXEC = shutil.which("mpiexec")
needs_mpi = pytest.mark.skipif(MPIEXEC is None, reason="mpiexec not found (make setup installs MPICH)")


def injected(ranks, setup, *argv):
    """`python -m ensemble argv` after `setup` (code using tests.inject), on `ranks` ranks (0: no mpiexec)."""
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; {setup}; "
            f"inject.main({list(map(str, argv))!r})")
    cmd = [sys.executable, "-c", code]
    return run_bounded(([MPIEXEC, "-n", str(ranks)] if ranks else []) + cmd, TIMEOUT, env=child_env())


def mpirun(ranks, *args):
    return run_bounded([MPIEXEC, "-n", str(ranks), sys.executable, "-m", "ensemble", *map(str, args)],
                       TIMEOUT, env=child_env())


@pytest.fixture(scope="module")
def branched(tmp_path_factory):
    """Two points x 3 seeds branched from their spin-ups, run serially: the reference (and its log)."""
    d = tmp_path_factory.mktemp("branch")
    cfg = write_config(d / "cfg.toml", model={"N": 40, "b": 20.0}, sweep={"b": [20.0, 50.0]},
                       run={"seeds": SEEDS, "events": EVENTS, "transient": SPINUP, "branch": True,
                            "decorrelation": DECORRELATE},
                       integrator={"rtol": 1e-5},
                       output={"batch": 10, "flush_seconds": 0.2})
    res = ensemble_here("run", cfg, "-o", d / "full.h5")
    assert res.returncode == 0, res.stderr
    return d, cfg, res.stdout


def per_task(events, k):
    mask = events["task"] == k
    return {name: values[mask] for name, values in events.items() if name != "task"}


def test_unperturbed_branches_continue_the_spun_up_trajectory_exactly(branched, tmp_path):
    """perturbation = 0: every seed of a point records exactly what its seed 0 records without
    branching, with a transient of the spin-up plus the decorrelation stretch."""
    d, cfg, _ = branched
    res = ensemble_here("run", cfg, "-o", tmp_path / "zero.h5", "--set", "run.perturbation=0")
    assert res.returncode == 0, res.stderr
    res = ensemble_here("run", cfg, "-o", tmp_path / "plain.h5", "--set", "run.branch=false",
                        "--set", f"run.transient={SPINUP + DECORRELATE}")
    assert res.returncode == 0, res.stderr
    zero, _, _ = reader.read(tmp_path / "zero.h5")
    plain, _, _ = reader.read(tmp_path / "plain.h5")
    for k in range(2 * SEEDS):
        a, b = per_task(zero, k), per_task(plain, k - k % SEEDS)
        assert len(a["t"]) == EVENTS
        for name in a:
            np.testing.assert_array_equal(a[name], b[name], err_msg=f"task {k} {name}")


def test_branches_differ_and_the_catalog_records_their_branch_point(branched):
    d, _, _ = branched
    events, tasks, attrs = reader.read(d / "full.h5")
    np.testing.assert_array_equal(tasks["branch_of"], np.repeat([0, 1], SEEDS))
    np.testing.assert_array_equal(tasks["events_written"], EVENTS)
    np.testing.assert_array_equal(tasks["events_done"], DECORRELATE + EVENTS)
    assert attrs["spinup"] == SPINUP and attrs["transient"] == DECORRELATE
    with h5py.File(d / "full.h5", "r") as h5:
        np.testing.assert_array_equal(h5["spinup/point"][...], [0, 1])
        np.testing.assert_array_equal(h5["spinup/spawn_key"][...], [0, SEEDS])   # each point's seed 0
        assert "run.branch" in h5["tasks/branch_of"].attrs["description"]
    assert_described(d / "full.h5", schema.DATASETS)
    assert set(descriptions(d / "full.h5")) == {name for name in schema.DATASETS if not name.startswith("histories/")}
    with reader.Reader(d / "full.h5") as cat:
        for point in (0, 1):
            head = cat.layout.head(2 * SEEDS + point)
            assert head.done == SPINUP and head.written == 0
            spun = cat.layout.read_state(2 * SEEDS + point, head)
            assert np.all(np.isfinite(spun.force)) and spun.clock[0] > 0
    for point in (0, 1):
        seqs = [per_task(events, point * SEEDS + s)["epicenter"] for s in range(SEEDS)]
        for s in range(1, SEEDS):
            assert not np.array_equal(seqs[0], seqs[s]), f"point {point}: seed {s} = seed 0"
        # all branch from the same spin-up: their first events start after the same clock
        starts = [per_task(events, point * SEEDS + s)["t"][0] for s in range(SEEDS)]
        assert max(starts) < 10 * min(starts)


@needs_mpi
@pytest.mark.mpi
# each writer once, and three ranks for two spin-ups (one rank idle until the branches); two ranks with the
# default writer are also the resumes of the interruption tests below
@pytest.mark.parametrize("ranks,writer", [pytest.param(2, "parallel", marks=pytest.mark.parallel_hdf5),
                                          (3, "rank0")])
def test_branching_is_independent_of_ranks_and_writer(branched, tmp_path, ranks, writer):
    d, cfg, _ = branched
    out = tmp_path / f"n{ranks}_{writer}.h5"
    res = mpirun(ranks, "run", cfg, "-o", out, "--set", f'output.writer="{writer}"')
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "full.h5", out)


def interrupted_spin_up(ranks, out, cfg):
    """A run stopped by SIGTERM in the middle of the spin-up of point 1: exit 75, no events.
    (Kernel calls of a few events each: the signal is served within a few events.)"""
    res = injected(ranks, f"inject.signal_in_spin_up({int(signal.SIGTERM)}, 1, {SPINUP // 3})",
                   "run", cfg, "-o", out, "--set", "run.poll_seconds=0.0001")
    assert res.returncode == 75, res.stdout + res.stderr
    with reader.Reader(partial_path(out)) as cat:
        assert cat.tasks["events_written"].sum() == 0
        heads = [cat.layout.head(k) for k in range(cat.layout.n_tasks, cat.layout.n_records)]
    return [0 if h is None else h.done for h in heads]


@pytest.mark.parametrize("ranks", [0, pytest.param(2, marks=[needs_mpi, pytest.mark.mpi])])
def test_interrupt_during_a_spin_up_resumes_to_the_uninterrupted_catalog(branched, tmp_path, ranks, capsys):
    d, cfg, _ = branched
    out = tmp_path / "spin.h5"
    done = interrupted_spin_up(ranks, out, cfg)
    assert 0 < done[1] < SPINUP        # checkpointed in the middle of the spin-up of point 1
    assert cli.main(["status", str(out)]) == 0     # (`python -m ensemble status`, in this process)
    status = capsys.readouterr().out
    assert f"spin-up of point 1: {done[1]}/{SPINUP} events (not done" in status, status
    res = mpirun(2, "resume", out) if ranks else ensemble_here("resume", out)
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "full.h5", out)


@pytest.mark.parametrize("ranks", [0, pytest.param(2, marks=[needs_mpi, pytest.mark.mpi])])
def test_interrupt_while_branching_resumes_to_the_uninterrupted_catalog(branched, tmp_path, ranks):
    d, cfg, _ = branched
    out = tmp_path / "branches.h5"
    res = injected(ranks, f"inject.signal_at_write({int(signal.SIGTERM)})", "run", cfg, "-o", out)
    assert res.returncode == 75, res.stdout + res.stderr
    _, tasks, _ = reader.read_tasks(partial_path(out))
    assert 0 < tasks["events_written"].sum() < 2 * SEEDS * EVENTS
    res = mpirun(2, "resume", out) if ranks else ensemble_here("resume", out)
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "full.h5", out)


def test_a_failed_spin_up_fails_its_points_tasks_and_a_rerun_completes_them(branched, tmp_path, monkeypatch):
    """The spin-up of point 1 fails half-way (injected; the run is in this process: a numerical failure needs
    no process of its own): its three tasks are failed, the others finish; a rerun with another rtol completes."""
    from ensemble.run import trajectory
    d, cfg, _ = branched
    out = tmp_path / "failed.h5"
    with monkeypatch.context() as patch:
        # monkeypatch keeps the original method, which it puts back at the end of this block over inject's patch
        patch.setattr(trajectory.Trajectory, "advance", trajectory.Trajectory.advance)
        inject.fail_spin_up(1, SPINUP // 2)
        res = ensemble_here("run", cfg, "-o", out)
    assert res.returncode == 1, res.stdout + res.stderr
    assert re.search(r"task [345]: spin-up of point 1 event \d+: injected failure", res.stdout)
    events, tasks, _ = reader.read(partial_path(out))
    np.testing.assert_array_equal(tasks["status"], [schema.FINISHED] * SEEDS + [schema.FAILED] * SEEDS)
    assert all("spin-up of point 1" in e for e in tasks["error"][SEEDS:])
    full, _, _ = reader.read(d / "full.h5")
    for k in range(SEEDS):      # the other point is unaffected
        np.testing.assert_array_equal(per_task(events, k)["t"], per_task(full, k)["t"])
    res = ensemble_here("resume", out)
    assert res.returncode == 1 and "failed: 3 of 6 tasks" in res.stdout
    res = ensemble_here("resume", out, "--set", "integrator.rtol=1e-6")
    assert res.returncode == 0, res.stderr
    _, tasks, _ = reader.read(out)
    np.testing.assert_array_equal(tasks["events_written"], EVENTS)
    assert all("rtol = 1e-06" in text for text in tasks["integrator"][SEEDS:])
    assert all("rtol = 1e-05" in text for text in tasks["integrator"][:SEEDS])


def test_validate_and_the_run_log_name_the_spin_ups(branched):
    d, cfg, log = branched
    res = ensemble_here("validate", cfg)
    assert res.returncode == 0, res.stderr
    assert (f"# spin-up of point 1: {SPINUP} events from task {SEEDS}'s initial state; tasks {SEEDS}-{2 * SEEDS - 1} "
            f"start from it, forces lowered by up to 1e-06, and discard {DECORRELATE} events") in res.stdout
    assert f"branching: 2 spin-up(s) of {SPINUP} events first" in log      # the reference run's


def test_branch_keys_are_validated_by_name():
    with pytest.raises(ConfigError, match=r"run\.branch must be true or false"):
        loads("[run]\nbranch = 1\n")
    with pytest.raises(ConfigError, match=r"run\.perturbation must be >= 0"):
        loads("[run]\nperturbation = -1e-6\n")
    with pytest.raises(ConfigError, match=r"run\.decorrelation must be an integer"):
        loads("[run]\ndecorrelation = 1.5\n")
    cfg = loads("[model]\nN = 400\n[sweep]\nN = [200, 300]\n[run]\nbranch = true\ntransient = 100\n")
    assert cfg.run.decorrelation == cfg.run.discarded == DECORRELATION_PER_BLOCK * 300   # the longest chain
    assert loads("[run]\ntransient = 100\n").run.discarded == 100


def test_a_branch_lowers_the_blocks_at_rest_and_keeps_the_creeping_ones_in_balance(tmp_path):
    """Below the block stiffness a spun-up state holds creeping blocks, whose force is their
    friction (the creep phase's force balance): the perturbation lowers only the blocks at rest,
    each by its own draw in [0, perturbation), and the branches run."""
    from ensemble.run.branching import branch_start, creeping
    from ensemble.config import load
    from ensemble.sweep import task_list
    perturbation = 1e-3
    # (rows end with every block at rest as a rule; at N = 200, b = 15 the 11th ends with one creeping)
    cfg_path = write_config(tmp_path / "creep.toml", model={"N": 200, "b": 15.0},
                            run={"seeds": 2, "events": 30, "transient": 11, "branch": True,
                                 "decorrelation": 10, "perturbation": perturbation})
    res = ensemble_here("run", cfg_path, "-o", tmp_path / "creep.h5")
    assert res.returncode == 0, res.stderr
    cfg = load(cfg_path)
    with reader.Reader(tmp_path / "creep.h5") as cat:
        layout = cat.layout
        spun = layout.read_state(layout.n_tasks, layout.head(layout.n_tasks))
    moving = creeping(spun)
    assert 0 < moving.sum() < len(moving), "the spin-up ends with some blocks creeping and some at rest"
    for task in task_list(cfg):
        start = branch_start(cfg, task, spun)
        np.testing.assert_array_equal(start.force[moving], spun.force[moving])
        lowered = spun.force[~moving] - start.force[~moving]
        assert np.all((lowered > 0) & (lowered < perturbation))
