"""Lazy loading and the onset tree between events (ensemble/model/schedule.py)."""
import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.schedule import tree_min, tree_set
from ensemble.model.workspace import D_DURATION, D_FIRST, D_LAST, D_SLIP, NDIAG, UNLIMITED, Workspace, tree_size

from .conftest import developed_state


def test_tree_finds_the_smallest_key_after_any_updates():
    rng = np.random.default_rng(0)
    for n in (1, 2, 7, 64, 1000):
        keys = np.full(n, np.inf)
        tree = np.full(tree_size(n), np.inf)
        for _ in range(3 * n):
            i = rng.integers(n)
            keys[i] = np.inf if rng.random() < 0.2 else rng.normal()
            tree_set(tree, i, keys[i])
            value, who = tree_min(tree)
            assert value == keys.min()
            if np.isfinite(value):
                assert keys[who] == value


def run_lazy(model, force, psi, events):
    ws = Workspace(model.N)
    ws.load(force, psi)
    clock = np.zeros(2)
    t, epi, diag = np.empty(events), np.empty(events, dtype=np.int64), np.empty((events, NDIAG))
    params = kernel_params(model, Integrator(method="rk4"))
    status, _ = simulate(ws.arrays, clock, params, events, UNLIMITED, t, epi, diag)
    assert status == 0
    return ws, clock, t, epi, diag


def test_lazy_schedule_equals_loading_every_block_every_event():
    """The same events and state as jumping all N blocks to each onset (the O(N) way)."""
    model = Model(N=200, b=20.0)
    force, psi = developed_state(model, 100)
    ws, clock, t, epi, diag = run_lazy(model, force, psi, 12)
    f, p = force, psi
    end = 0.0   # of the previous event
    eager_end = 0.0
    for k in range(12):
        epicenter, delay, f, p = advance_to_onset(f, p, model)
        f[epicenter] = model.b * p[epicenter]
        ev = check(run_event(f, p, epicenter, model, Integrator(method="rk4")))
        assert epicenter == epi[k]
        print(f"event {k}: onset delay {(t[k] - end) / delay - 1:.1e}, slip {ev.slip / diag[k, D_SLIP] - 1:.1e}, "
              f"duration {ev.duration / diag[k, D_DURATION] - 1:.1e} relative")
        # An onset is where the force (rate nu) overtakes the threshold (rate b / theta,
        # often close to nu): nearly tangent, so a round-off difference of the forces
        # moves it by many orders of magnitude more. Measured: up to 7.5e-9 relative.
        assert t[k] - end == pytest.approx(delay, rel=1e-7)
        # measured up to 1.0e-10
        assert ev.slip == pytest.approx(diag[k, D_SLIP], rel=1e-9)
        # the last stick is a near-tangency of v(t) = 0: durations are far more sensitive than
        # slips (measured up to 2.4e-6)
        assert ev.duration == pytest.approx(diag[k, D_DURATION], rel=1e-4)
        end = t[k] + diag[k, D_DURATION]
        eager_end += delay + ev.duration
        f, p = ev.force, ev.psi
    # Onsets being ill-conditioned (above: up to ~7 time units apart), the two runs
    # stop and restart blocks at slightly different times: theta (which grows by 1
    # per unit time at rest) and the forces (nu per unit time) may differ by that much.
    # Measured: forces 4.0e-7 apart (bound 1.2e-6), theta 7.5e-9 relative (39 absolute, of ~5e9).
    lazy_force, lazy_psi = ws.state(clock, kernel_params(model, Integrator(method="rk4")))
    print(f"after 12 events: forces {np.max(np.abs(lazy_force - f)):.1e} apart (nu * slack = {model.nu * 20:.0e}), "
          f"theta {np.max(np.abs(np.exp(lazy_psi) / np.exp(p) - 1)):.1e} relative, "
          f"{np.max(np.abs(np.exp(lazy_psi) - np.exp(p))):.1e} absolute")
    slack = 20.0
    np.testing.assert_allclose(lazy_force, f, rtol=0, atol=model.nu * slack + 1e-6)   # forces are O(1e3)
    np.testing.assert_allclose(np.exp(lazy_psi), np.exp(p), rtol=1e-7, atol=slack)   # onsets: 1e-7, above


def test_an_event_updates_only_the_blocks_it_touched():
    """Blocks outside the rupture and its two neighbours keep their stored state untouched."""
    model = Model(N=400, b=20.0)
    force, psi = developed_state(model, 100)
    ws = Workspace(model.N)
    ws.load(force, psi)
    clock = np.zeros(2)
    t, epi, diag = np.empty(1), np.empty(1, dtype=np.int64), np.empty((1, NDIAG))
    params = kernel_params(model, Integrator(method="rk4"))
    small = 0
    for _ in range(60):
        before = ws.W.copy(), ws.since.copy()
        assert simulate(ws.arrays, clock, params, 1, UNLIMITED, t, epi, diag)[0] == 0
        changed = np.flatnonzero((ws.W != before[0]).any(axis=1) | (ws.since != before[1]).any(axis=1))
        lo, hi = int(diag[0, D_FIRST]), int(diag[0, D_LAST])
        if hi - lo < 20:
            small += 1
            # the rupture, its neighbours, and at most the blocks whose loading onset was checked
            assert changed.min() >= min(lo, epi[0]) - 1 and changed.max() <= max(hi, epi[0]) + 1
    assert small >= 10
