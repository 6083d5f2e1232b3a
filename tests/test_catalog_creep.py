"""The catalog of a chain that creeps (bk-catalog-8): inertial events and creep episodes as rows of
/events (`kind`, `ending`), each record's creep state in its checkpoint slots where its chain can creep
(/checkpoint/creep), statistics of the inertial events alone, and a run interrupted with creep in flight,
or run on two ranks, that writes the uninterrupted serial catalog.

The chain is below the block stiffness (b = 15 < 1 + 2 l^2 = 19, N = 50): every block can creep, and
about three rows in four are creep episodes. A point at b = 25 beside it cannot creep: its records keep
no creep state, so one catalog holds slots of both sizes.
"""
import shutil
import signal
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from analysis import export, summary
from ensemble.store import layout, reader, schema, writers
from ensemble.store.checkpoint import Checkpoint, carries_creep
from ensemble.store.errors import CatalogError
from ensemble.store.files import partial_path
from ensemble.model.workspace import CS_NCREEP, NCSTATE, Workspace

from . import reduction_reference as ref
from .conftest import run_cli, write_config
from .processes import ROOT, child_env, run_bounded
from .same_catalogs import assert_same_events

TIMEOUT = 300
SEEDS, EVENTS, TRANSIENT = 2, 200, 20
CREEPING, STIFF = 15.0, 25.0      # model.b of the two points: below and above the block stiffness 19
# ark4, with creep phases integrated at a looser tolerance than the default 1e-6 (creep_tol 1e-4: a creeping
# task in a third of the time, still three rows in four creep): what is tested here is how the catalog keeps
# both kinds and the creep state, not the accuracy of the creep
INTEGRATOR = {"method": "ark4", "creep_tol": 1e-4}


def injected(setup, *argv, ranks=None):
    """`python -m ensemble argv` after `setup` (code using tests.inject), under mpiexec -n ranks if given."""
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; {setup}; "
            f"inject.main({list(map(str, argv))!r})")
    cmd = [sys.executable, "-c", code]
    if ranks:
        cmd = [shutil.which("mpiexec"), "-n", str(ranks), *cmd]
    return run_bounded(cmd, TIMEOUT, env=child_env())


@pytest.fixture(scope="module")
def creeping(tmp_path_factory):
    """The config (b = 15 and 25, two seeds each, INTEGRATOR, defaults otherwise) and its uninterrupted
    serial catalog."""
    d = tmp_path_factory.mktemp("creep_catalog")
    cfg = write_config(d / "cfg.toml", model={"N": 50}, sweep={"b": [CREEPING, STIFF]},
                       run={"seeds": SEEDS, "events": EVENTS, "transient": TRANSIENT},
                       integrator=INTEGRATOR, output={"batch": 50, "flush_seconds": 1000.0})
    res = run_cli("run", cfg, "-o", d / "full.h5", timeout=TIMEOUT)
    assert res.returncode == 0, res.stdout + res.stderr
    return d, cfg


def tasks_of(tasks, b):
    return np.flatnonzero(tasks["b"] == b)


def test_a_creeping_chain_writes_both_kinds_and_keeps_its_creep_state(creeping):
    d, _ = creeping
    events, tasks, attrs = reader.read(d / "full.h5")
    assert attrs["format"] == schema.FORMAT == "bk-catalog-8"
    kind, ending = events["kind"], events["ending"]
    assert kind.dtype == ending.dtype == np.int8
    for k in tasks_of(tasks, CREEPING):
        mine = events["task"] == k
        inertial, creep = mine & (kind == 0), mine & (kind == 1)
        assert np.count_nonzero(inertial) >= 30 and np.count_nonzero(creep) >= 30, (k, np.bincount(kind[mine]))
        assert np.all(ending[inertial] == 0) and np.all(np.isin(ending[creep], (1, 2)))
        assert np.all(np.diff(events["t"][inertial]) >= 0)       # events in time order among themselves
        assert np.all(events["duration"][creep] > 0) and np.all(events["slip"][creep] > 0)
        # a stress drop for each inertial event (tests/test_physics.py checks its value), none for an episode
        assert np.all(events["stress_drop"][inertial] > 0) and np.all(np.isnan(events["stress_drop"][creep]))
    stiff = np.isin(events["task"], tasks_of(tasks, STIFF))
    assert stiff.any() and np.all(kind[stiff] == 0) and np.all(ending[stiff] == 0)
    # the checkpoint slots: a creep state where the chain can creep, none where it cannot
    with h5py.File(d / "full.h5", "r") as h5:
        flags = h5["checkpoint/creep"][...].astype(np.int64)
        np.testing.assert_array_equal(flags, tasks["b"] == CREEPING)
        slot = 4 * 50 + 2 + flags * Workspace.creep_size(50)
        np.testing.assert_array_equal(h5["checkpoint/offset"][...], np.concatenate([[0], np.cumsum(2 * slot)[:-1]]))
        assert h5["checkpoint/state"].shape == (2 * slot.sum(),)
        assert "0 an inertial event, 1 a creep episode" in h5["events/kind"].attrs["description"]
    with reader.Reader(d / "full.h5") as cat:
        for k in range(len(tasks["point"])):
            state = cat.layout.read_state(k, cat.layout.head(k))
            if flags[k]:
                assert state.creep is not None and len(state.creep) == Workspace.creep_size(50)
                assert 0 <= state.creep[-NCSTATE + CS_NCREEP] <= 50
            else:
                assert state.creep is None
    # the export carries both columns, with their meanings
    table = export.events(d / "full.h5")
    np.testing.assert_array_equal(table["kind"], kind)
    np.testing.assert_array_equal(table["ending"], ending)
    assert export.columns(d / "full.h5", "events")["ending"] == schema.DATASETS["events/ending"][::2]


def test_a_catalog_of_the_format_before_reads_without_stress_drops(tmp_path):
    """A bk-catalog-6 catalog (the committed one of tests/test_summary_identity.py, with creep episodes) reads:
    every column it stores as stored (its events checksum covers those), the stress drop NaN; the export writes
    the column; a run of it is not continued: one line naming its format, the file unchanged."""
    import gzip
    old = tmp_path / "format6.h5"
    with gzip.open(f"{ROOT}/tests/data/summary_reference_catalog.h5.gz") as src, open(old, "wb") as dst:
        shutil.copyfileobj(src, dst)
    events, _, attrs = reader.read(old)
    assert attrs["format"] == "bk-catalog-6"
    assert np.count_nonzero(events["kind"] == 1) > 0 and np.all(np.isnan(events["stress_drop"]))
    with h5py.File(old, "r") as h5:
        assert "stress_drop" not in h5["events"]
        for name in schema.STORED_EVENT_FIELDS["bk-catalog-6"]:
            np.testing.assert_array_equal(events[name], h5["events"][name][...][:len(events[name])], err_msg=name)
    assert np.all(np.isnan(export.events(old)["stress_drop"]))
    part = Path(partial_path(tmp_path / "format6-resume.h5"))
    shutil.copy(old, part)
    before = part.read_bytes()
    res = run_cli("resume", tmp_path / "format6-resume.h5")
    assert res.returncode == 1 and "bk-catalog-6" in res.stderr and len(res.stderr.strip().splitlines()) == 1, \
        res.stderr
    assert part.read_bytes() == before


def test_reduce_counts_the_inertial_events_alone(creeping):
    """The summary of the catalog equals the reference reduction of its kind-0 rows alone (every dataset:
    R(mu), recurrence times, GR b, fraction large, per-task stretches and their bootstrap)."""
    from analysis import cli
    d, _ = creeping
    out = d / "sum.h5"
    assert cli.main(["reduce", str(d / "full.h5"), "-o", str(out), "--bootstrap", "50", "--mu-c", "3.5"]) == 0
    events, tasks, _ = reader.read(d / "full.h5")
    inertial = {name: column[events["kind"] == schema.KIND_EVENT] for name, column in events.items()}
    opt = {"mu_edges": np.linspace(0, 7, 71), "tnu_edges": np.linspace(0, 2000, 81), "mu_c": 3.5,
           "window": 10, "b_cut": 3.0, "bootstrap": 50, "level": 0.95, "blocks": 20, "seed": 0}
    expected = ref.expected_summary([(d / "full.h5", events, tasks)], opt)   # the reference keeps kind 0 apart
    ref.check_summary(ref.read_summary(out), expected, opt)
    # (what that covers: creep rows that would change every statistic of the creeping point)
    s = summary.read(out)
    creeping_point = int(np.flatnonzero(s["points/b"] == CREEPING)[0])
    assert s["points/numbers/n_events"][creeping_point][0] == np.count_nonzero(
        np.isin(inertial["task"], tasks_of(tasks, CREEPING))) < SEEDS * EVENTS
    assert s["points/numbers/n_recurrences"][creeping_point][0] > 10
    creep_mu = events["mu"][events["kind"] == schema.KIND_CREEP]
    assert np.count_nonzero((creep_mu >= 0) & (creep_mu < 7)) > 50     # they would land in R(mu)'s bins


def test_compare_counts_the_inertial_events_alone(creeping):
    """`analysis compare`'s tables (sizes, magnitudes, recurrences: the engine's, reduced with its set of
    statistics) read the kind-0 rows alone."""
    from analysis import compare, options, reduce
    d, _ = creeping
    events, tasks, _ = reader.read(d / "full.h5")
    opt = options.make("compare", blocks=5, window=10, n_large=40, n_min=1)
    ids = [int(k) for k in tasks_of(tasks, CREEPING)]
    per_task = reduce.reduce_tasks(str(d / "full.h5"), ids, opt, compare.LAYOUT)
    for k in ids:
        inertial = (events["task"] == k) & (events["kind"] == schema.KIND_EVENT)
        np.testing.assert_array_equal(per_task[k]["n_slipped"].sum(axis=0),
                                      np.bincount(events["n_slipped"][inertial], minlength=51))
        assert per_task[k]["mu"].sum() == np.count_nonzero(inertial)


@pytest.mark.parametrize("paused", [False, True], ids=["creeping", "creeping-and-paused"])
def test_resume_with_creep_in_flight_gives_the_uninterrupted_catalog(creeping, tmp_path, paused):
    """SIGTERM when a kernel call ends with blocks creeping (and an event paused): every task checkpoints
    its creep state, and the resumed catalog is the uninterrupted one, row for row."""
    d, cfg = creeping
    out = tmp_path / "cut.h5"
    # kernel calls of 1000 block-steps (worker.MIN_BUDGET) from the first on: most events pause many times
    setup = (f"from ensemble.run import worker; worker.FIRST_BUDGET = 1000; "
             f"inject.signal_when_creeping({int(signal.SIGTERM)}, paused={paused})")
    res = injected(setup, "run", cfg, "-o", out, "--set", "run.poll_seconds=1e-5")
    assert res.returncode == 75, res.stdout + res.stderr
    with reader.Reader(partial_path(out)) as cat:
        states = [cat.layout.read_state(k, cat.layout.head(k)) for k in tasks_of(cat.tasks, CREEPING)
                  if cat.layout.head(k) is not None]
        stopped = [k for k in range(len(cat.tasks["point"])) if 0 < cat.tasks["events_done"][k] < TRANSIENT + EVENTS]
    # the stop came with blocks creeping: some task's checkpoint holds them
    assert any(s.creep[-NCSTATE + CS_NCREEP] > 0 for s in states), "no checkpoint with creep in flight"
    assert stopped, "every task had finished or not begun"
    # the rest in kernel calls sized as usual (as in the uninterrupted run): the catalog does not depend on them
    res = run_cli("resume", out, "--set", "run.poll_seconds=0.25", timeout=TIMEOUT)
    assert res.returncode == 0, res.stdout + res.stderr
    assert_same_events(d / "full.h5", out)
    a, _, _ = reader.read(d / "full.h5")
    b, _, _ = reader.read(out)
    for name in schema.EVENT_FIELDS:          # and in the same order of rows
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
@pytest.mark.parametrize("writer", ["rank0", pytest.param("parallel", marks=pytest.mark.parallel_hdf5)])
def test_two_ranks_write_the_serial_catalog(creeping, tmp_path, writer):
    d, cfg = creeping
    out = tmp_path / f"two-{writer}.h5"
    res = run_bounded([shutil.which("mpiexec"), "-n", "2", sys.executable, "-m", "ensemble", "run", str(cfg),
                       "-o", str(out), "--set", f'output.writer="{writer}"'], TIMEOUT, env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    assert_same_events(d / "full.h5", out)
    _, tasks, _ = reader.read(out)
    assert set(tasks["rank"]) == {0, 1}
    with h5py.File(d / "full.h5", "r") as one, h5py.File(out, "r") as two:
        np.testing.assert_array_equal(one["checkpoint/creep"][...], two["checkpoint/creep"][...])


def test_a_checkpoint_packs_its_creep_state_and_a_slot_of_another_size_is_refused(tmp_path):
    n = 5
    rng = np.random.default_rng(3)
    cp = Checkpoint(rng.random(n), rng.random(n), rng.random((n, 2)), rng.random(2), 7,
                            rng.random(Workspace.creep_size(n)))
    flat = cp.pack()
    assert len(flat) == 4 * n + 2 + Workspace.creep_size(n)
    back = Checkpoint.unpack(flat, 7, n)
    for name in ("force", "psi", "since", "clock", "creep"):
        np.testing.assert_array_equal(getattr(back, name), getattr(cp, name), err_msg=name)
    assert Checkpoint.unpack(flat[:4 * n + 2], 7, n).creep is None
    # a writer refuses a checkpoint that does not fit the record's slots (with or without a creep state)
    from mpi4py import MPI

    from ensemble.config import loads
    from ensemble.run.trajectory import integrator_text
    from ensemble.sweep import task_list
    cfg = loads(f"[model]\nN = {n}\nb = 15.0\n[run]\nevents = 4\ntransient = 0\n")
    assert carries_creep(cfg.model) and not carries_creep(loads("[model]\nN = 5\n").model)
    writer = writers.Rank0Writer(str(tmp_path / "c.h5"), MPI.COMM_SELF, cfg, task_list(cfg),
                                 integrator_text(cfg.integrator))
    try:
        writer.record(0)
        no_creep = Checkpoint(cp.force, cp.psi, cp.since, cp.clock, 0)
        with pytest.raises(CatalogError,
                           match=r"a checkpoint of 22 values for slots of \d+ \(with a creep state\)"):
            writer.commit(0, 0, None, no_creep)
        writer.commit(0, 0, None, Checkpoint(cp.force, cp.psi, cp.since, cp.clock, 0, cp.creep))
    finally:
        writer.close()
    with reader.Reader(tmp_path / "c.h5") as cat:
        np.testing.assert_array_equal(cat.layout.read_state(0, cat.layout.head(0)).creep, cp.creep)


def test_unperturbed_branches_carry_the_spun_up_creep_state(tmp_path):
    """run.branch with perturbation 0: every seed records what its seed 0 records without branching. The
    spin-up is made to end with a block creeping (the first such row count, found by running the chain
    here), so the branches need its creep state, not only its forces and states. Seed 0 without branching
    is that same chain run on here (as a run's task does: a Trajectory, event_rows), past the branches'
    decorrelation."""
    from ensemble.config import loads
    from ensemble.run.trajectory import Trajectory, event_rows
    from ensemble.sweep import task_list
    run = {"seeds": 2, "events": 60, "transient": 40, "branch": True, "decorrelation": 20, "perturbation": 0.0}
    cfg = write_config(tmp_path / "branch.toml", model={"N": 50, "b": CREEPING}, run=run, integrator=INTEGRATOR)
    seed0 = task_list(loads(cfg.read_text()))[0]
    chain = Trajectory(loads(cfg.read_text()), seed0)
    while chain.ws.cstate[CS_NCREEP] == 0 or chain.done < 20:
        chain.advance(1)
        assert chain.done < 1000, "no row count after which a block creeps"
    cfg = write_config(tmp_path / "branch.toml", model={"N": 50, "b": CREEPING}, run={**run, "transient": chain.done},
                       integrator=INTEGRATOR)
    res = run_cli("run", cfg, "-o", tmp_path / "zero.h5", timeout=TIMEOUT)
    assert res.returncode == 0, res.stdout + res.stderr
    chain.advance(run["decorrelation"])
    plain = event_rows(seed0, *chain.advance(run["events"]))
    assert len(plain["t"]) == run["events"] and np.count_nonzero(plain["kind"] == schema.KIND_CREEP) > 10
    zero, _, _ = reader.read(tmp_path / "zero.h5")
    with reader.Reader(tmp_path / "zero.h5") as cat:     # the spin-up (record 2) ended with a block creeping
        spun = cat.layout.read_state(2, cat.layout.head(2))
    assert spun.creep is not None and spun.creep[-NCSTATE + CS_NCREEP] > 0
    for k in range(2):
        mine = zero["task"] == k
        for name in schema.EVENT_FIELDS:
            if name != "task":
                np.testing.assert_array_equal(zero[name][mine], plain[name], err_msg=f"task {k} {name}")


def test_a_record_laid_out_for_another_kernel_is_not_continued(tmp_path, monkeypatch):
    """A resume asks whether each record's slots hold a creep state exactly where this version's kernel
    keeps one (a kernel whose creep criterion changed could not restore, or store, the state)."""
    from mpi4py import MPI

    from ensemble.config import loads
    from ensemble.run.trajectory import integrator_text
    from ensemble.sweep import task_list
    cfg = loads("[model]\nN = 5\nb = 15.0\n[run]\nevents = 4\ntransient = 0\n")
    path = str(tmp_path / "c.h5")
    writers.Rank0Writer(path, MPI.COMM_SELF, cfg, task_list(cfg), integrator_text(cfg.integrator)).close()
    reader.read(path)                                   # a reader does not ask
    monkeypatch.setattr(layout, "carries_creep", lambda model: False)    # what a resume asks
    reader.read(path)
    writer = writers.Rank0Writer(path, MPI.COMM_SELF)
    try:
        with pytest.raises(CatalogError, match="task 0: its checkpoint slots were laid out with a creep "
                                                       "state, and this version keeps none"):
            writer.record(0)
    finally:
        writer.close()
