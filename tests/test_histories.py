"""Event histories (output.history; ensemble/model/history.py, ensemble/store/histories.py): recording them changes
no event of the catalog, bit for bit; each is the event it names (its end is the event's slip profile, summing to
its slip, at its duration), sampled from the onset by velocity and by time; they are the first recorded events of
their magnitude; two ranks under mpiexec and a run killed between a history and its commit give the same.
"""
import shutil
import sys

import h5py
import numpy as np
import pytest

from ensemble.store import reader, schema
from ensemble.store.files import partial_path

from .conftest import run_cli, write_config
from .processes import ROOT, analysis_here, child_env, run_bounded
from .same_catalogs import assert_same_events

TIMEOUT = 300
MU = 2.0          # output.history_mu: at N = 100, b = 20 about one event in ten
PER_TASK = 3
HISTORY = {"history": PER_TASK, "history_mu": MU, "history_snapshots": 2000, "history_dt": 0.1,
           "history_dlogv": 0.2}


def config(d, **output):
    return write_config(d / f"cfg{len(output)}.toml", model={"N": 100, "b": 20.0},
                        run={"seeds": 2, "events": 150, "transient": 50}, output={"batch": 40, **output})


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The same config without histories, with them, and with them in buffers of 8 snapshots; serial."""
    d = tmp_path_factory.mktemp("histories")
    out = {}
    for name, extra in (("plain", {}), ("recorded", HISTORY), ("cramped", {**HISTORY, "history_snapshots": 8})):
        res = run_cli("run", config(d, **extra), "-o", d / f"{name}.h5", timeout=TIMEOUT)
        assert res.returncode == 0, res.stdout + res.stderr
        out[name] = d / f"{name}.h5"
    return d, out


def histories_of(path):
    with reader.Reader(path) as cat:
        return [cat.histories(k) for k in range(len(cat.tasks["point"]))], cat.per_task


def test_recording_changes_no_event(runs):
    _, out = runs
    assert_same_events(out["plain"], out["recorded"])
    plain, _ = histories_of(out["plain"])
    assert all(h == [] for h in plain)
    # the group only where asked for, every dataset of it described (schema.DATASETS)
    with h5py.File(out["plain"], "r") as a, h5py.File(out["recorded"], "r") as b:
        assert "histories" not in a
        names = [f"histories/{name}" for name in b["histories"]]
        assert sorted(names) == sorted(n for n in schema.DATASETS if n.startswith("histories/"))
        for name in names:
            assert b[name].attrs["description"] == schema.description(schema.DATASETS[name])


def test_a_history_is_its_event_from_onset_to_end(runs):
    _, out = runs
    events, _, _ = reader.read(out["recorded"])
    histories, per_task = histories_of(out["recorded"])
    for task, kept in enumerate(histories):
        mine = {name: col[events["task"] == task] for name, col in events.items()}
        # the first PER_TASK recorded inertial events of mu >= MU, in order
        first = np.flatnonzero((mine["mu"] >= MU) & (mine["kind"] == 0))[:PER_TASK]
        assert [h["row"] for h in kept] == list(first) and len(first) == PER_TASK
        for h in kept:
            row, time, v, y = h["row"], h["time"], h["velocity"], h["slip"]
            # the end is the event's: its slip profile, summing to its slip, at its duration, all at rest
            assert y[-1].sum() == pytest.approx(mine["slip"][row], rel=1e-12)
            assert time[-1] == mine["duration"][row] and not v[-1].any()
            slipped = np.flatnonzero(y[-1] > 0)
            assert (slipped[0], slipped[-1], len(slipped)) == (mine["first"][row], mine["last"][row],
                                                              mine["n_slipped"][row])
            # from the onset (the epicenter alone, nothing slipped yet), in time, blocks never moving back
            assert time[0] == 0 and np.all(np.diff(time) > 0) and not y[0].any()
            assert np.all(np.diff(y, axis=0) >= 0) and np.all(v >= 0)
            assert np.argmax(v[1]) == mine["epicenter"][row]
            # sampled by time (history_dt) and by velocity (history_dlogv): no gap longer than the step after
            # history_dt, the largest velocity rising through several decades before the rupture
            vmax = v.max(axis=1)
            assert h["dropped"] == 0 and len(time) > 20
            assert vmax.max() / vmax[1] > 100
            # the slip of each snapshot is the time integral of the velocity: trapezoids between snapshots, to
            # the sampling's accuracy (history_dt 0.1: measured up to 4.6e-3 of the largest slip)
            integral = np.concatenate([np.zeros((1, v.shape[1])),
                                       np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(time)[:, None], axis=0)])
            off = np.abs(integral - y).max() / y[-1].max()
            print(f"row {row}: {len(time)} snapshots; trapezoids of v against the slip: {off:.1e} of the largest")
            assert off < 1e-2


def test_a_full_buffer_keeps_the_end(runs):
    """Eight snapshots a history: the first seven as the full recording's, the eighth its end, the rest counted as
    dropped."""
    _, out = runs
    full, _ = histories_of(out["recorded"])
    cramped, _ = histories_of(out["cramped"])
    for whole, short in zip(full, cramped):
        for a, b in zip(whole, short):
            assert a["row"] == b["row"] and len(b["time"]) == 8 and b["dropped"] == len(a["time"]) - 8
            for name in ("time", "sliding", "velocity", "slip"):
                np.testing.assert_array_equal(b[name][:7], a[name][:7], err_msg=name)
                np.testing.assert_array_equal(b[name][7], a[name][-1], err_msg=name)


@pytest.mark.slow    # (a run under mpiexec, 6 s: the slower tier, run by CI)
def test_two_ranks_write_the_same_histories(runs):
    d, out = runs
    mpi = d / "mpi.h5"
    res = run_bounded([shutil.which("mpiexec"), "-n", "2", sys.executable, "-m", "ensemble", "run",
                       str(config(d, **HISTORY)), "-o", str(mpi)], TIMEOUT, env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    assert_same_events(out["recorded"], mpi)
    same_histories(out["recorded"], mpi)


def same_histories(a, b):
    ha, _ = histories_of(a)
    hb, _ = histories_of(b)
    assert len(ha) == len(hb)
    for x, y in zip(ha, hb):
        assert len(x) == len(y) == PER_TASK
        for p, q in zip(x, y):
            assert p["row"] == q["row"] and p["dropped"] == q["dropped"]
            for name in ("time", "sliding", "velocity", "slip"):
                np.testing.assert_array_equal(p[name], q[name], err_msg=name)


@pytest.mark.slow    # (three runs, 10 s: the slower tier, run by CI)
def test_a_run_killed_between_a_history_and_its_commit_resumes_to_the_same(runs):
    """Killed (as by kill -9) just before the commit row of a batch with a history of task 0, after an earlier
    commit (batches of 5 rows): the history and the events are written and flushed, not committed; a reader sees
    the histories of the committed rows alone, the resumed task writes that one again (the same: a run is
    deterministic), and the catalog is the uninterrupted one's."""
    d, out = runs
    cfg = config(d, **HISTORY, batch=5)
    log = d / "writes.log"
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; "
            f"inject.log_writes({str(log)!r}); inject.main(['run', {str(cfg)!r}, '-o', {str(d / 'logged.h5')!r}])")
    res = run_bounded([sys.executable, "-c", code], TIMEOUT, env=child_env())
    assert res.returncode == 0, res.stderr
    writes = [(int(line.split()[0]), line.split()[2:]) for line in log.read_text().splitlines()]
    commits = [k for k, what in writes if what == ["/checkpoint/commit"]]
    rows = [k for k, what in writes if what == ["/histories/row"]][:PER_TASK]      # task 0's (it runs first)
    row = next(k for k in rows if k > commits[0])
    at = next(k for k in commits if k > row)      # dies just before it
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; "
            f"inject.crash_at_write({at}); inject.main(['run', {str(cfg)!r}, '-o', {str(d / 'killed.h5')!r}])")
    res = run_bounded([sys.executable, "-c", code], TIMEOUT, env=child_env())
    assert res.returncode == 99, res.stderr
    # what the test stands on: task 0 has committed rows, and a history in the file of a row not committed
    _, tasks, _ = reader.read(partial_path(d / "killed.h5"))
    with h5py.File(partial_path(d / "killed.h5"), "r") as h5:
        slots = h5["histories/row"][:PER_TASK]
    written = tasks["events_written"][0]
    assert written > 0 and np.any((slots >= 0) & (slots < written)) and np.any(slots >= written), (slots, written)
    # a reader of the killed run sees the histories of its committed rows alone
    with reader.Reader(partial_path(d / "killed.h5")) as cat:
        assert [h["row"] for h in cat.histories(0)] == [int(r) for r in slots if 0 <= r < written]
    res = run_cli("resume", d / "killed.h5", timeout=TIMEOUT)
    assert res.returncode == 0, res.stdout + res.stderr
    assert_same_events(out["recorded"], d / "killed.h5")
    same_histories(out["recorded"], d / "killed.h5")


def test_analysis_history_draws_one_and_says_which(runs, tmp_path):
    _, out = runs
    res = analysis_here("history", out["recorded"], "--task", "1", "--index", "2", "-o", tmp_path / "h.png")
    assert res.returncode == 0, res.stderr
    events, _, _ = reader.read(out["recorded"])
    histories, _ = histories_of(out["recorded"])
    row = histories[1][2]["row"]
    mu = events["mu"][events["task"] == 1][row]
    assert f"task 1 (N = 100, l = 3, a = 0, b = 20), row {row}: mu = {mu:.2f}" in res.stdout
    assert (tmp_path / "h.png").stat().st_size > 10_000
    # none there: one line naming the file, exit 1, no figure
    for path, args in ((out["plain"], ()), (out["recorded"], ("--index", str(PER_TASK)))):
        res = analysis_here("history", path, *args, "-o", tmp_path / "none.png")
        assert res.returncode == 1 and len(res.stderr.strip().splitlines()) == 1 and str(path) in res.stderr
        assert not (tmp_path / "none.png").exists()


def test_the_nucleation_columns_are_where_the_history_says():
    """A history of every step (history_dt tiny) against the kernel's nucleation columns of the same events
    (in-process, a Trajectory): t_spread is the step before the first snapshot in which more blocks than the
    onset's have moved (a block starts at rest, at the end of the step that starts it), n_widest the most blocks
    sliding in a snapshot and t_widest the first snapshot with that many; 1 block at each onset (b = 20: no
    creep)."""
    from ensemble.config import loads
    from ensemble.run.trajectory import Trajectory, event_rows
    from ensemble.sweep import task_list
    cfg = loads("[model]\nN = 100\nb = 20.0\n[run]\nevents = 100\ntransient = 50\n[output]\nhistory = 4\n"
                "history_mu = 2.0\nhistory_snapshots = 20000\nhistory_dt = 1e-12\n")
    traj = Trajectory(cfg, task_list(cfg)[0], histories=0)
    rows = []
    while traj.done < 150:
        rows.append(traj.advance(10))
    ev = event_rows(traj.task, *(np.concatenate([r[j] for r in rows]) for j in range(3)))
    assert len(traj.new_histories) == 4
    for _, h in traj.new_histories:
        row = 50 + h["row"]
        time, moved = h["time"], np.count_nonzero((h["velocity"] > 0) | (h["slip"] > 0), axis=1)
        assert h["dropped"] == 0 and ev["n_onset"][row] == 1 and h["sliding"][0] == 1
        grown = int(np.argmax(moved > 1))
        widest = int(np.argmax(h["sliding"]))
        assert ev["t_spread"][row] == time[grown - 1]
        assert ev["n_widest"][row] == h["sliding"][widest] > 1 and ev["t_widest"][row] == time[widest]
        print(f"row {row}: t_spread {ev['t_spread'][row]:.4g}, widest {ev['n_widest'][row]} blocks at "
              f"{ev['t_widest'][row]:.4g}, {len(time)} snapshots")
