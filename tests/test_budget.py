"""Kernel calls bounded by work (chain.simulate's budget): a paused event continues exactly.

Any budget must give the events of one unlimited call bit for bit, and while an event is
paused the workspace must give back the exact state after the last completed event
(Workspace.between_events), from which a fresh workspace continues bit for bit: that is what a
checkpoint taken during a long event holds.

No tolerances: everything is compared bit for bit. The counts asserted are coverage (the
pauses did fall inside events): measured 12-16 of 16 events paused in, 4-6 resumed in a fresh
workspace, against at least 8 and 3.
"""
import ast
import inspect

import numpy as np
import pytest

from ensemble.store.checkpoint import Checkpoint
from ensemble.config import Config, Integrator, Model, Run
from ensemble.integrators import kernel_params
from ensemble.model import event, workspace
from ensemble.model.chain import simulate
from ensemble.model.workspace import F0, NDIAG, OK, P, PAUSED, UNLIMITED, PausedEvent, Workspace
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list

MODELS = {"b = 20": Model(N=60, b=20.0), "a = 2": Model(N=60, b=20.0, a=2.0)}
METHODS = ["rk4", "ark4"]


def fresh(model, seed=3):
    """A workspace with a random initial state (the first events are large), and its clock."""
    rng = np.random.default_rng(seed)
    ws = Workspace(model.N)
    ws.load(-rng.random(model.N), np.zeros(model.N))
    return ws, np.zeros(2)


def outputs(n):
    return np.empty(n), np.empty(n, dtype=np.int64), np.empty((n, NDIAG))


def run_with_budget(ws, clock, params, n, budget):
    """n events in calls of `budget` work units; (onsets, epicenters, diagnostics, calls that paused)."""
    out = outputs(n)
    done = paused = 0
    while done < n:
        status, k = simulate(ws.arrays, clock, params, n - done, budget, *(a[done:] for a in out))
        assert status in (OK, PAUSED)
        paused += status == PAUSED
        done += k
    return (*out, paused)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", MODELS)
def test_any_budget_gives_the_same_events_and_state(name, method):
    """The budgets 1 and 7 pause after every work unit or every few (rk4: 150 000 to 310 000 pauses in the
    first five events, large ones from the random start; each pause costs a kernel call, hence five events
    there, not twenty)."""
    model = MODELS[name]
    params = kernel_params(model, Integrator(method=method))
    for budget, n in ((1, 5), (7, 5), (100, 20), (10**9, 20)):
        ws_ref, clock_ref = fresh(model)
        *ref, _ = run_with_budget(ws_ref, clock_ref, params, n, UNLIMITED)
        ws, clock = fresh(model)
        *got, paused = run_with_budget(ws, clock, params, n, budget)
        for a, b in zip(got, ref):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(clock, clock_ref)
        for a, b in zip(ws.arrays, ws_ref.arrays):     # every work array, scratch included
            np.testing.assert_array_equal(a, b)
        assert (paused == 0) if budget == 10**9 else (paused > n)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", MODELS)
def test_between_events_state_of_a_paused_event(name, method):
    """Paused anywhere, the state handed out is exactly the one after the last completed event,
    the workspace is left alone, and a fresh workspace loaded with it continues bit for bit."""
    model, n = MODELS[name], 16
    params = kernel_params(model, Integrator(method=method))
    ws, clock = fresh(model)
    after = []      # exact between-events state after k events, k = 0..n
    ref = outputs(n)
    for k in range(n):
        after.append((ws.force.copy(), ws.psi.copy(), ws.since.copy(), clock.copy()))
        assert simulate(ws.arrays, clock, params, 1, UNLIMITED, *(a[k:k + 1] for a in ref)) == (OK, 1)
    after.append((ws.force.copy(), ws.psi.copy(), ws.since.copy(), clock.copy()))

    ws, clock = fresh(model)
    rng = np.random.default_rng(0)
    got = outputs(n)
    done = pauses = resumed = 0
    paused_in = set()     # events paused in the middle of
    while done < n:
        status, k = simulate(ws.arrays, clock, params, n - done, int(10 ** rng.uniform(0, 4)),
                             *(a[done:] for a in got))
        done += k
        if status != PAUSED:
            continue
        pauses += 1
        live = [a.copy() for a in ws.arrays] + [clock.copy()]
        state = ws.between_events(clock)
        for a, b in zip(state, after[done]):
            np.testing.assert_array_equal(a, b)
        for a, b in zip(live, list(ws.arrays) + [clock]):
            np.testing.assert_array_equal(a, b)
        if done % 3 == 0 and done not in paused_in:   # resume in a fresh workspace (tree rebuilt)
            force, psi, since, c = state
            other = Workspace(model.N)
            other.load(force, psi, since)
            rest = outputs(n - done)
            assert simulate(other.arrays, c, params, n - done, UNLIMITED, *rest) == (OK, n - done)
            for a, b in zip(rest, ref):
                np.testing.assert_array_equal(a, b[done:])
            for a, b in zip(other.between_events(c), after[n]):
                np.testing.assert_array_equal(a, b)
            resumed += 1
        paused_in.add(done)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)
    print(f"{pauses} pauses in {len(paused_in)} of {n} events, {resumed} resumed in a fresh workspace")
    assert len(paused_in) >= n // 2 and resumed >= 3


def test_trajectory_checkpoint_during_a_paused_event():
    """The runner's Trajectory: a checkpoint taken while an event is paused resumes exactly."""
    cfg = Config(model=Model(N=60, b=20.0, a=2.0), run=Run(), integrator=Integrator(method="ark4"))
    task = task_list(cfg)[0]
    whole = Trajectory(cfg, task)
    t_ref, epi_ref, diag_ref = whole.advance(24)
    traj = Trajectory(cfg, task)
    parts = [traj.advance(5)]
    while not traj.ws.paused:
        parts.append(traj.advance(24 - traj.done, budget=300))
    cp = traj.checkpoint()
    assert cp.done == traj.done and cp.done < 24
    resumed = Trajectory(cfg, task, Checkpoint(cp.force, cp.psi, cp.since, cp.clock, cp.done, cp.creep))
    parts.append(resumed.advance(24 - resumed.done))
    for col, ref in enumerate((t_ref, epi_ref, diag_ref)):
        np.testing.assert_array_equal(np.concatenate([p[col] for p in parts]), ref)
    # the paused trajectory itself finishes the same way
    while traj.done < 24:
        traj.advance(24 - traj.done, budget=300)
    np.testing.assert_array_equal(traj.clock, whole.clock)
    np.testing.assert_array_equal(traj.ws.W[:, [F0, P]], whole.ws.W[:, [F0, P]])


# -- the paused event's record ------------------------------------------------------------------

def _slots():
    """{EV_ name: slot} of the event-state vector (workspace.py)."""
    return {name: value for name, value in vars(workspace).items() if name.startswith("EV_")}


def test_the_event_state_slots_are_one_each_and_contiguous():
    """Each name of the event-state vector has a slot of its own, and the slots fill the vector. (The
    vector never reaches a file: a checkpoint holds the between-events state, Workspace.between_events,
    and a paused event is integrated again from its onset, so only this holds the slots in place.)"""
    slots = _slots()
    assert sorted(slots.values()) == list(range(workspace.NEVENT)), slots
    assert {f"EV_{field.upper()}" for field in PausedEvent._fields} <= set(slots)


def test_the_paused_event_is_saved_and_restored_by_name():
    """_keep puts each field of the record into its slot (field x into EV_X) and _resume reads it back
    from there, whatever the order of the record's fields: a record of distinct values comes back whole,
    and each value sits in the slot of its name (run as Python: the same code numba compiles)."""
    counts = {"na", "nt", "far", "steps", "block_steps", "rejected", "cuts", "traced", "still"}
    values = {f: (k + 2 if f in counts else k + 2.5) for k, f in enumerate(PausedEvent._fields)}
    record = PausedEvent(**values)
    vector = np.full(workspace.NEVENT, np.nan)
    event._keep.py_func(vector, record)
    slots = _slots()
    assert {f: vector[slots[f"EV_{f.upper()}"]] for f in PausedEvent._fields} == values
    back = event._resume.py_func(vector)
    assert back == record
    assert {f: type(getattr(back, f)) for f in counts} == {f: int for f in counts}
    # the record is built by keyword wherever the kernel builds it, so no call depends on the fields' order
    tree = ast.parse(inspect.getsource(event))
    calls = [node for node in ast.walk(tree)
             if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "PausedEvent"]
    assert calls and all(not call.args and {k.arg for k in call.keywords} == set(PausedEvent._fields) for call in calls)


# -- steps that stop advancing time --------------------------------------------------------------

@pytest.mark.parametrize("budget", [UNLIMITED, 7])
def test_steps_that_stop_advancing_time_end_the_event_over_any_budget(budget):
    """The guard behind event.STALL_STEPS: an adaptive method whose largest step is 0 (the config refuses it;
    here the record is built by hand) takes steps of no length after its first. The event ends with STALLED
    after STALL_STEPS of them, counted over paused calls too: with a budget of 7 work units a call takes a few
    steps, so a count that started again at every call would never get there (the task ran until max_steps)."""
    model = MODELS["b = 20"]
    params = kernel_params(model, Integrator(method="ark4"))._replace(max_step=0.0)
    ws, clock = fresh(model)
    out = outputs(1)
    calls = 0
    while True:
        status, k = simulate(ws.arrays, clock, params, 1, budget, *out)
        calls += 1
        if status != PAUSED and not (status == OK and k == 0):
            break
        assert calls < 10 * event.STALL_STEPS, "the event never stalled"
    assert (status, k) == (workspace.STALLED, 0)
    steps = ws.arrays.event[workspace.EV_STEPS]
    assert event.STALL_STEPS <= steps <= event.STALL_STEPS + 2, steps
    assert calls == 1 if budget == UNLIMITED else calls > 100
