"""Friction laws as plug-ins: each law's analytic identities, onset, convergence, energy, runs.

The aging law's kernels are covered by test_physics, test_onset, test_convergence and the
others; this file holds the checks of every other law (docs/laws.md), today Carlson-Langer:

    Phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)) for v > 0, static threshold 1, no state,
    the loader standing still during events (an event takes no loading time).

Layers as in STYLE.md: analytic solutions (one block, one block among resting ones, the N = 1
cycle), the onset against brute-force loading, the convergence order of an event's slip, the
energy balance, RK4 against ARK4 on a short run, rank invariance, then config and catalog.
"""
import math
import shutil
import sys

import h5py
import numpy as np
import pytest

from ensemble.store import reader
from ensemble.config import Integrator, Model, loads
from ensemble.events import advance_to_onset, check, run_event
from ensemble.integrators import kernel_params
from ensemble.model import laws
from ensemble.model.chain import simulate
from ensemble.model.workspace import D_DURATION, D_NSLIP, D_SLIP, NDIAG, PAUSED, UNLIMITED, Workspace

from .conftest import developed_state, run_cli
from .processes import child_env, run_bounded
from .same_catalogs import assert_same_events

CL = "carlson-langer"
RK4 = Integrator(method="rk4", dt=1e-3)


def cl_model(N, alpha=2.5, sigma=0.01, l=3.0, nu=0.01):
    return Model(N=N, l=l, nu=nu, law=CL, alpha=alpha, sigma=sigma)


def run_chain(model, integrator, n, seed=1):
    """n events of simulate() from a seeded random start (forces in (-1, 0], psi = 0):
    (onset times, epicenters, diagnostics rows)."""
    rng = np.random.default_rng(seed)
    ws = Workspace(model.N)
    ws.load(-rng.random(model.N), np.zeros(model.N))
    clock = np.zeros(2)
    t, epicenter, diag = np.empty(n), np.empty(n, dtype=np.int64), np.empty((n, NDIAG))
    status, k = simulate(ws.arrays, clock, kernel_params(model, integrator), n, UNLIMITED, t, epicenter, diag)
    assert status == 0 and k == n
    return t, epicenter, diag


def next_onset(force, psi, model):
    """Load to the next onset; the epicenter exactly on its threshold 1 (as simulate does)."""
    epicenter, _, f, p = advance_to_onset(force, psi, model)
    f[epicenter] = 1.0
    return epicenter, f, p


# -- 1. analytic: one block ---------------------------------------------------------------------

def linear_slip(alpha, sigma, k):
    """Slip of u'' - 2 alpha u' + k u = sigma from u = u' = 0 until u' = 0 again (t = pi / omega).

    The block starts at force 1 on its threshold; friction linearised about v = 0+ is
    (1 - sigma) - 2 alpha v, so the net force is sigma - k u + 2 alpha u'; with
    omega = sqrt(k - alpha^2), u = (sigma / k) (1 - e^{alpha t} (cos wt - (alpha / w) sin wt)).
    """
    omega = math.sqrt(k - alpha ** 2)
    return sigma / k * (1.0 + math.exp(alpha * math.pi / omega)), math.pi / omega


@pytest.mark.parametrize("alpha", [0.0, 0.5])
def test_single_block_slip_is_the_linearised_oscillation(alpha):
    """N = 1 (stiffness 1): slip sigma (1 + exp(alpha pi / omega)) over pi / omega, omega = sqrt(1 - alpha^2).

    The linearisation of Phi drops 4 alpha^2 v^2 / (1 - sigma) and smaller, with v ~ sigma, so its
    relative error is O(sigma) (and 0 at alpha = 0, where friction is the constant 1 - sigma):
    two sigmas 100x apart must give errors ~100x apart.
    """
    errors = {}
    for sigma in (1e-4, 1e-6):
        model = Model(N=1, l=3.0, nu=0.01, law=CL, alpha=alpha, sigma=sigma)
        ev = check(run_event(np.array([1.0]), np.array([0.0]), 0, model, RK4))
        slip, duration = linear_slip(alpha, sigma, 1.0)
        errors[sigma] = (ev.slip / slip - 1, ev.duration / duration - 1)
        # the loader stands still: the block ends at force 1 - slip, and no loading work is done
        assert ev.force[0] == pytest.approx(1.0 - ev.slip, rel=1e-15)
        assert ev.load_work == 0.0
    print(f"alpha = {alpha}: relative errors (slip, duration) against the linear theory: "
          + ", ".join(f"sigma {s:g}: {e[0]:.2e}, {e[1]:.2e}" for s, e in errors.items()))
    if alpha == 0.0:
        # exact up to RK4's error at dt = 1e-3 and round-off: measured 1.1e-13 and 2.9e-11 in slip
        # (the latter is round-off of a slip of 2e-6), 6.9e-14 and 3.5e-13 in duration
        for slip_error, duration_error in errors.values():
            assert abs(slip_error) < 1e-9 and abs(duration_error) < 1e-9
    else:
        # measured -5.25e-4 (sigma 1e-4) and -5.26e-6 (1e-6): -5.25 sigma, ratio 99.9;
        # durations -1.12e-4 and -1.13e-6
        (e4, d4), (e6, d6) = errors[1e-4], errors[1e-6]
        assert 3e-4 < -e4 < 8e-4 and 3e-6 < -e6 < 8e-6
        assert 80 < e4 / e6 < 120
        assert 80 < d4 / d6 < 120


@pytest.mark.parametrize("block,stiffness", [(10, 19.0), (0, 10.0)])
@pytest.mark.parametrize("alpha", [0.0, 2.5])
def test_block_among_resting_neighbours(block, stiffness, alpha):
    """A block of a chain whose other blocks stay at rest (force 0.5, far below 1) slides alone.

    The resting neighbours act as fixed springs: stiffness k = 1 + 2 l^2 inside the chain, 1 + l^2
    at an end, so omega = sqrt(k - alpha^2) and the slip is (sigma / k) (1 + exp(alpha pi / omega)).
    The neighbours gain l^2 times that slip, ~1e-4, and must not start.
    """
    errors = {}
    for sigma in (1e-4, 1e-6):
        model = cl_model(N=21, alpha=alpha, sigma=sigma)
        force = np.full(model.N, 0.5)
        force[block] = 1.0
        ev = check(run_event(force, np.zeros(model.N), block, model, RK4))
        slipped = np.flatnonzero(ev.profile)
        assert list(slipped) == [block], slipped
        slip, duration = linear_slip(alpha, sigma, stiffness)
        errors[sigma] = (ev.slip / slip - 1, ev.duration / duration - 1)
        # the neighbours took the spring's load, nothing else moved
        expected = force.copy()
        expected[block] = 1.0 - stiffness * ev.slip
        for j in (block - 1, block + 1):
            if 0 <= j < model.N:
                expected[j] = 0.5 + model.l ** 2 * ev.slip
        np.testing.assert_allclose(ev.force, expected, rtol=0, atol=1e-15)
    print(f"block {block} (k = {stiffness:g}), alpha = {alpha}: relative errors (slip, duration) "
          + ", ".join(f"sigma {s:g}: {e[0]:.2e}, {e[1]:.2e}" for s, e in errors.items()))
    (e4, d4), (e6, d6) = errors[1e-4], errors[1e-6]
    if alpha == 0.0:
        # measured at most 1.1e-12 (slip) and 4.9e-12 (duration)
        assert max(abs(e4), abs(e6), abs(d4), abs(d6)) < 1e-9
    else:
        # O(sigma) with a coefficient that grows with the amplification exp(alpha pi / omega)
        # (9 inside, 57 at the end): measured slip -1.12e-3 / -1.12e-5 inside, -2.10e-2 / -2.16e-4
        # at the end (ratios 100 and 97); durations -2.5e-4 / -2.5e-6 and -4.4e-3 / -4.5e-5
        assert abs(e4) < 0.05
        assert 80 < e4 / e6 < 120 and 80 < d4 / d6 < 120


# -- 2. the N = 1 cycle -------------------------------------------------------------------------

def test_single_block_cycle_loader_still_during_events():
    """One block, many events: each starts on the threshold 1 and ends at 1 - slip with the loader
    still, so every event is the same and the loader advances by the slip between onsets."""
    model = Model(N=1, l=3.0, nu=0.01, law=CL, alpha=0.5, sigma=0.01)
    ws = Workspace(1)
    ws.load(np.array([0.3]), np.zeros(1))
    clock = np.zeros(2)
    n = 400
    t, epicenter, diag = np.empty(n), np.empty(n, dtype=np.int64), np.empty((n, NDIAG))
    status, k = simulate(ws.arrays, clock, kernel_params(model, RK4), n, UNLIMITED, t, epicenter, diag)
    assert status == 0 and k == n
    slip, duration = diag[:, D_SLIP], diag[:, D_DURATION]
    loader = model.nu * np.diff(t)
    spread = np.ptp(slip) / slip[0]
    mismatch = np.max(np.abs(loader / slip[:-1] - 1))
    alone = check(run_event(np.array([1.0]), np.array([0.0]), 0, model, RK4))
    print(f"N = 1, {n} events: slip {slip[0]:.10f} (spread {spread:.1e}), duration {duration[0]:.6f} "
          f"(spread {np.ptp(duration):.1e}); nu dt / slip - 1 at most {mismatch:.1e}; first onset {t[0]}")
    # the first onset from force 0.3: (1 - 0.3) / nu
    assert t[0] == pytest.approx(0.7 / model.nu, rel=1e-14)
    # every event the same: measured spread 0 in slip and duration
    assert spread < 1e-13 and np.ptp(duration) < 1e-13 * duration[0]
    assert slip[0] == pytest.approx(alone.slip, rel=1e-13)
    # nu (t_{k+1} - t_k) = slip_k; t reaches ~2700, whose ulp (4.5e-13) is 7e-14 of an interval:
    # measured 6.4e-14. A loader moving during events would add nu * duration (~1e-2 relative)
    assert mismatch < 1e-12
    # the state after the last event: force 1 - slip, psi 0
    force, psi = ws.state(clock, kernel_params(model, RK4))
    assert force[0] == pytest.approx(1.0 - slip[-1], rel=1e-14) and psi[0] == 0.0


@pytest.mark.parametrize("method", ["rk4", "ark4"])
def test_paused_and_restored_run_equals_uninterrupted(method):
    """With the clock left at the onset during an event (loader still), a run cut by small work
    budgets, each call restarting from a fresh workspace loaded with its checkpoint (mid-event:
    the state before the event), gives the uninterrupted run's events bit for bit."""
    model = cl_model(N=50)
    integrator = Integrator(method=method)
    n = 200
    reference = run_chain(model, integrator, n)
    p = kernel_params(model, integrator)
    rng = np.random.default_rng(1)
    force, psi, since, clock = -rng.random(model.N), np.zeros(model.N), np.zeros((model.N, 2)), np.zeros(2)
    parts, calls, paused, budget = [], 0, 0, 2000
    while sum(len(part[0]) for part in parts) < n:
        assert calls < 5000, "no progress"
        ws = Workspace(model.N)
        ws.load(force, psi, since)
        left = n - sum(len(part[0]) for part in parts)
        t, epicenter, diag = np.empty(left), np.empty(left, dtype=np.int64), np.empty((left, NDIAG))
        status, k = simulate(ws.arrays, clock, p, left, budget, t, epicenter, diag)
        calls += 1
        paused += status == PAUSED
        # the paused event is redone from the state before it: an event longer than the budget
        # needs a larger one to finish (rk4's events take ~10x the block-steps of ark4's)
        budget = 2 * budget if k == 0 else 2000
        parts.append((t[:k], epicenter[:k], diag[:k]))
        force, psi, since, clock = ws.between_events(clock)
    print(f"{method}: {calls} calls, {paused} paused in an event")
    assert paused > 5
    for ours, theirs in zip((np.concatenate(x) for x in zip(*parts)), reference):
        np.testing.assert_array_equal(ours, theirs)


# -- 3. onset ------------------------------------------------------------------------------------

@pytest.mark.parametrize("nu", [1e-8, 1e-2, 1.0])
def test_onset_delay_matches_brute_force(nu):
    """onset_delay is the time at which F + nu t, stepped from t = 0, first reaches the law's threshold."""
    law = laws.get(CL)
    params = law.kernel_params(cl_model(N=2))
    threshold = law.threshold(params, 0.0)
    assert threshold == 1.0
    rng = np.random.default_rng(5)
    gaps = np.concatenate([np.geomspace(1e-12, 5.0, 100), rng.uniform(0.0, 6.0, 100)])
    imbalance, steps = [], []
    for gap in gaps:
        F = 1.0 - gap
        d = law.onset_delay(params, F, 0.0, nu)
        assert d > 0
        # at the onset the force is on the threshold, up to the roundings of F and of nu * d
        imbalance.append(abs(F + nu * d - threshold) / max(1.0, abs(F)))
        # brute force: step the load by h = gap / (999.5 nu) until it reaches the threshold: in step
        # 1000, and the onset must lie inside it, half a step from either end (for gaps well above
        # round-off: at 1e-8 one ulp of the force is 1e-5 of a step)
        if gap >= 1e-8:
            h = gap / (999.5 * nu)
            load = F + nu * h * np.arange(1, 1101)
            k = int(np.argmax(load >= threshold)) + 1
            steps.append(k)
            assert (k - 1) * h < d <= k * h, (gap, k, d / h)
    print(f"nu {nu}: force imbalance at the onset at most {max(imbalance):.1e} of max(1, |F|); brute force "
          f"reached the threshold in step {min(steps)} .. {max(steps)} (of h = gap / 999.5 nu)")
    # (1 - F) / nu * nu is 1 - F up to two roundings: measured at most 2.5e-16 (of max(1, |F|))
    assert max(imbalance) <= 4.5e-16
    assert set(steps) == {1000}
    # a block on or above its threshold starts at once
    assert law.onset_delay(params, 1.0, 0.0, nu) == 0.0
    assert law.onset_delay(params, 1.5, 0.0, nu) == 0.0


def test_advance_to_onset_picks_the_largest_force():
    """No state: every block loads at nu towards the same threshold, so the largest force starts first."""
    model = cl_model(N=300)
    rng = np.random.default_rng(7)
    force = 1.0 - rng.uniform(0.01, 3.0, model.N)
    epicenter, delay, f, psi = advance_to_onset(force, np.zeros(model.N), model)
    print(f"epicenter {epicenter} (argmax {np.argmax(force)}), delay {delay:.6f} = (1 - max F) / nu "
          f"{(1 - force.max()) / model.nu:.6f}; epicenter's force - 1 = {f[epicenter] - 1:.1e}")
    assert epicenter == int(np.argmax(force))
    assert delay == pytest.approx((1.0 - force.max()) / model.nu, rel=1e-14)
    assert abs(f[epicenter] - 1.0) <= 2e-16
    np.testing.assert_allclose(f, force + model.nu * delay, rtol=0, atol=1e-15)
    assert np.all(np.delete(f, epicenter) < 1.0) and np.all(psi == 0.0)


# -- 4. convergence ------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def multi_block_events():
    """The first three events of several blocks (>= 5) after 300 events of a chain of 50, each with
    its pre-event state and a reference: RK4 at dt = 1.25e-4."""
    model = cl_model(N=50)
    force, psi = developed_state(model, 300)
    out = []
    while len(out) < 3:
        epicenter, f, p = next_onset(force, psi, model)
        ref = check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=1.25e-4)))
        if np.count_nonzero(ref.profile) >= 5:
            out.append((f, p, epicenter, ref))
        force, psi = ref.force, ref.psi
    return model, out


def test_event_slip_converges_with_order_4_rk4(multi_block_events):
    """RK4 at dt, dt/2, dt/4: slip and profile errors (against the reference and between
    successive dt) fall 2^p-fold, p ~ 4, sticks and onsets located inside steps included."""
    model, events = multi_block_events
    dts = [4e-3, 2e-3, 1e-3]
    for f, p, epicenter, ref in events:
        runs = [check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=dt))) for dt in dts]
        slips = np.array([ev.slip for ev in runs])
        err = np.abs(slips - ref.slip)
        perr = np.array([np.linalg.norm(ev.profile - ref.profile) for ev in runs])
        d = np.abs(np.diff(slips))
        orders = np.log2(err[:-1] / err[1:]), np.log2(perr[:-1] / perr[1:]), np.log2(d[:-1] / d[1:])
        print(f"event at {epicenter}: {np.count_nonzero(ref.profile)} blocks, slip {ref.slip:.4f}, relative "
              f"slip errors {err / ref.slip}; orders slip {orders[0]}, profile {orders[1]}, differences {orders[2]}")
        # measured 3.99 .. 4.01 (slip, profile, differences) on the three events; an order-3
        # method or transition location fails 3.5, as does clamping v at step ends (order 2).
        # The reference's own error is ~(1.25e-4 / 1e-3)^4 = 2.4e-4 of that at dt = 1e-3.
        for o in orders:
            assert np.all(o >= 3.5) and np.all(o <= 4.6), orders
        assert err[-1] < 1e-8 * ref.slip


def test_event_slip_error_of_ark4_follows_its_tolerance(multi_block_events):
    """ARK4 (for this law its explicit tableau alone) at rtol 1e-4 .. 1e-8: the slip error against
    the reference falls with rtol, about in proportion, and stays within a modest multiple of it."""
    model, events = multi_block_events
    rtols = np.array([1e-4, 1e-5, 1e-6, 1e-7, 1e-8])
    for f, p, epicenter, ref in events:
        err = np.array([abs(check(run_event(f, p, epicenter, model, Integrator(method="ark4", rtol=r))).slip
                            / ref.slip - 1) for r in rtols])
        slope = np.polyfit(np.log10(rtols), np.log10(err), 1)[0]
        print(f"event at {epicenter}: ark4 relative slip error / rtol {err / rtols}, slope {slope:.2f}")
        # measured error / rtol between 0.31 and 124 (the largest at small rtol: a control of the error
        # per step gives error ~ rtol^(4/5) rather than ~ rtol), slopes 0.85 .. 1.03 (0.70 on another
        # event, seen with friction changed); a tolerance that no longer steers the error gives ~0
        assert np.all(err <= 500 * rtols)
        assert 0.6 <= slope <= 1.3


# -- 5. energy ---------------------------------------------------------------------------------

def test_energy_balance_per_event():
    """dE_elastic + friction work = 0 for every event: the loader stands still, so it does no work.

    The elastic change is also recomputed from the slip profile and the pre-event forces:
    dE = -sum(y F) + sum(y^2) / 2 + l^2 sum(diff(y)^2) / 2.
    """
    model = cl_model(N=50)
    force, psi = developed_state(model, 300)
    rows = []
    for _ in range(30):
        epicenter, f, p = next_onset(force, psi, model)
        ev = check(run_event(f, p, epicenter, model, RK4))
        ark = check(run_event(f, p, epicenter, model, Integrator(method="ark4")))
        y = ev.profile
        elastic = -np.sum(y * f) + 0.5 * np.sum(y * y) + 0.5 * model.l ** 2 * np.sum(np.diff(y) ** 2)
        rows.append((ev.relative_energy_residual, abs(ev.energy_residual / ev.friction_work),
                     abs(ev.elastic_change / elastic - 1), ev.load_work, ark.load_work,
                     ark.relative_energy_residual, np.count_nonzero(y)))
        force, psi = ev.force, ev.psi
    relative, per_friction, mismatch, load, ark_load, ark_relative, blocks = np.array(rows).T
    print(f"30 events ({int(blocks.min())} .. {int(blocks.max())} blocks), RK4 dt = 1e-3: |residual| / "
          f"energy scale at most {relative.max():.1e}, / friction work {per_friction.max():.1e}; elastic "
          f"term against the profile {mismatch.max():.1e}; ARK4 rtol 1e-5: {ark_relative.max():.1e}")
    assert np.all(load == 0.0) and np.all(ark_load == 0.0)
    # measured 1.6e-11 (RK4's truncation error at dt = 1e-3), and 3.4e-11 against the friction work
    assert relative.max() < 1e-9 and per_friction.max() < 2e-9
    # round-off: measured 2.2e-16
    assert mismatch.max() < 1e-12
    # ARK4 at its default rtol 1e-5 conserves energy to about its tolerance: measured 3.2e-6
    assert ark_relative.max() < 3e-5


# -- 7. RK4 against ARK4 ---------------------------------------------------------------------

def test_rk4_and_ark4_agree_on_a_short_run():
    """The same start, RK4 at dt = 1e-3 and ARK4 at rtol 1e-7: the first 20 events one by one,
    the magnitudes of 600 events (after 100) in distribution.

    The chain is chaotic: per-event differences (~1e-7) grow from event to event. With seed 1
    the first mu difference above 1e-6 comes at event 25 and the epicenters part at event 41;
    other seeds part earlier (seed 4: 1e-3 within 20 events), hence the fixed seed.
    """
    model = cl_model(N=50)
    n = 600
    t_a, epi_a, diag_a = run_chain(model, RK4, n)
    t_b, epi_b, diag_b = run_chain(model, Integrator(method="ark4", rtol=1e-7), n)
    mu_a, mu_b = np.log10(diag_a[:, D_SLIP]), np.log10(diag_b[:, D_SLIP])
    dmu = np.abs(mu_a - mu_b)[:20]
    # An onset is where the loader has made up the slips since the start, so its error (as the
    # loader's displacement nu t) is bounded by the slip accumulated before it, times ~rtol.
    accumulated = np.concatenate([[0.0], np.cumsum(diag_a[:19, D_SLIP])])
    dload = model.nu * np.abs(t_a[:20] - t_b[:20]) / accumulated.clip(1e-300)
    print(f"first 20 events: largest |d mu| {dmu.max():.1e}; onsets: loader displacement off by at most "
          f"{dload.max():.1e} of the slip accumulated (by then {accumulated[-1]:.3f})")
    np.testing.assert_array_equal(epi_a[:20], epi_b[:20])
    # measured 3.9e-7 (mu) and 2.2e-6 (onsets); at alpha = 2, 2.75: 2.7e-7, 3.0e-7 and 3.9e-6,
    # 2.2e-6 (alpha = 2.75 with a whole-chain event of slip 33 among the 20)
    assert dmu.max() < 2e-6 and dload.max() < 2e-5

    def stats(mu, nslip):
        mu, nslip = mu[100:], nslip[100:]
        return {"mean mu": mu.mean(), "one block": np.mean(nslip == 1), "mu > -1": np.mean(mu > -1),
                "median mu": np.median(mu), "mean blocks": nslip.mean()}
    sa, sb = stats(mu_a, diag_a[:, D_NSLIP]), stats(mu_b, diag_b[:, D_NSLIP])
    print("500 events, RK4 / ARK4: " + ", ".join(f"{k} {sa[k]:.4f} / {sb[k]:.4f}" for k in sa))
    # Seeds 1-5 (ARK4 at rtol 1e-5 and 1e-7): differences up to 0.080 (mean mu), 0.060 (fraction of
    # one-block events), 0.024 (fraction above mu = -1), 0.28 (mean blocks); seed 1 here: 0.003,
    # 0.002, 0.010, 0.16. The median is the one-block event, the same slip in both up to rtol.
    assert abs(sa["mean mu"] - sb["mean mu"]) < 0.15
    assert abs(sa["one block"] - sb["one block"]) < 0.1
    assert abs(sa["mu > -1"] - sb["mu > -1"]) < 0.05
    assert abs(sa["mean blocks"] - sb["mean blocks"]) < 0.5
    assert abs(sa["median mu"] - sb["median mu"]) < 1e-5


# -- 6, 8, 9: runs, config and catalog ----------------------------------------------------------

def write_cl_config(path, events=3000, transient=200, **model):
    """The small Carlson-Langer config: N = 50, alpha = 2.5, sigma = 0.01, nu = 0.01, two seeds."""
    keys = {"N": 50, "l": 3.0, "nu": 0.01, "law": CL, "alpha": 2.5, "sigma": 0.01, **model}
    lines = ["[model]"] + [f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v!r}" for k, v in keys.items()]
    lines += ["", "[run]", "seeds = 2", f"events = {events}", f"transient = {transient}", "",
              "[integrator]", 'method = "ark4"', "", "[output]", f'path = "{path.with_suffix(".h5")}"',
              "batch = 500", ""]
    path.write_text("\n".join(lines))
    return path


@pytest.fixture(scope="module")
def cl_run(tmp_path_factory):
    """The small config run serially (2 tasks x 3000 events after 200: ~1 s)."""
    d = tmp_path_factory.mktemp("laws")
    cfg = write_cl_config(d / "cl.toml")
    res = run_cli("run", cfg, "-o", d / "serial.h5")
    assert res.returncode == 0, res.stderr
    return d, cfg


@pytest.mark.mpi
@pytest.mark.parametrize("writer", ["auto", "rank0"])
def test_catalog_independent_of_ranks(cl_run, writer):
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec not found (make setup installs MPICH)")
    d, cfg = cl_run
    out = d / f"n2_{writer}.h5"
    res = run_bounded([mpiexec, "-n", "2", sys.executable, "-m", "ensemble", "run", cfg, "-o", out,
                       "--set", f'output.writer="{writer}"'], 300, env=child_env())
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "serial.h5", out)
    _, tasks, _ = reader.read(out)
    assert len(tasks["rank"]) == 2 and set(tasks["rank"]) <= {0, 1}


def one_error_line(res):
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), res.stderr
    return lines[0]


KEY_ERRORS = [
    (f'[model]\nlaw = "{CL}"\nb = 30.0\n', f"model.b does not belong to model.law = '{CL}' (its keys: alpha, sigma)"),
    (f'[model]\nlaw = "{CL}"\n[sweep]\nb = [20.0, 30.0]\n', f"sweep.b does not belong to model.law = '{CL}'"),
    ("[model]\nalpha = 2.0\n", "model.alpha does not belong to model.law = 'aging' (its keys: a, b, c)"),
    ('[model]\nlaw = "coulomb"\n', "model.law must be one of aging, carlson-langer, slip, got 'coulomb'"),
    # a law that cannot creep asked to creep
    (f'[model]\nlaw = "{CL}"\n[integrator]\ncreep_tol = 1e-5\n',
     f"integrator.creep_tol = 1e-05: model.law = '{CL}' has no creep phase"),
]


# Every error under `validate`; `run` reads the config through the same call (cli._config), so one error
# shows its handler (one line, exit status 2, no catalog) without a process per message.
@pytest.mark.parametrize("command,text,words", [("validate", *case) for case in KEY_ERRORS]
                         + [("run", *KEY_ERRORS[0])])
def test_a_key_of_another_law_is_an_error_naming_it(tmp_path, command, text, words):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    out = ["-o", tmp_path / "never.h5"] if command == "run" else []
    line = one_error_line(run_cli(command, cfg, *out))
    assert words in line and str(cfg) in line, line
    assert not (tmp_path / "never.h5").exists()


OVERRIDE_ERRORS = [("model.b=30", "model.b"), ("sweep.b=[20.0, 30.0]", "sweep.b"), ("model.a=1.0", "model.a"),
                   ('model.law="aging"', "model.alpha")]


# (as above: every override under `validate`, one under `run`)
@pytest.mark.parametrize("command,override,key", [("validate", *case) for case in OVERRIDE_ERRORS]
                         + [("run", *OVERRIDE_ERRORS[-1])])
def test_an_override_of_another_law_is_an_error_naming_it(cl_run, tmp_path, command, override, key):
    d, cfg = cl_run
    out = ["-o", tmp_path / "never.h5"] if command == "run" else []
    line = one_error_line(run_cli(command, cfg, *out, "--set", override))
    assert f"{key} does not belong to model.law" in line, line
    assert not (tmp_path / "never.h5").exists()


def test_catalog_records_the_law(cl_run):
    """/tasks/law and its conventions, the law's keys per task, NaN for the other law's keys."""
    d, cfg = cl_run
    events, tasks, attrs = reader.read(d / "serial.h5")
    assert list(tasks["law"]) == [CL, CL]
    assert list(tasks["alpha"]) == [2.5, 2.5] and list(tasks["sigma"]) == [0.01, 0.01]
    for name in ("a", "b", "c"):
        assert np.all(np.isnan(tasks[name])), name
    with h5py.File(d / "serial.h5") as h5:
        conventions = h5["tasks/law"].attrs["conventions"]
    assert conventions.startswith(f"{CL}: ") and "aging" not in conventions
    assert "loader stands still during events" in conventions
    stored = loads(attrs["config"])
    assert stored.model.law == CL and stored.model.alpha == 2.5 and stored.model.b is None
    assert len(events["t"]) == 6000 and np.all(np.isfinite(events["mu"]))
    # with the loader still during events, onsets are on the loading clock: no two coincide
    for k in (0, 1):
        assert np.all(np.diff(events["t"][events["task"] == k]) > 0)


def test_status_reduce_and_report_on_a_carlson_langer_catalog(cl_run, tmp_path):
    d, cfg = cl_run
    res = run_cli("status", d / "serial.h5")
    assert res.returncode == 0, res.stderr
    header = next(line for line in res.stdout.splitlines() if line.lstrip().startswith("task"))
    assert header.split()[:6] == ["task", "point", "seed", "N", "alpha", "sigma"], header
    assert " 2.5 " in res.stdout and " 0.01 " in res.stdout
    summary = tmp_path / "sum.h5"
    analysis = [sys.executable, "-m", "analysis"]
    # Carlson-Langer magnitudes (log10 slip) lie around -2.3 .. 1.5, T nu around 0 .. 2
    res = run_bounded([*analysis, "reduce", d / "serial.h5", "-o", summary, "--bootstrap", "20",
                       "--mu-bins=-3:2:50", "--tnu-bins=0:2:40", "--mu-c=-1", "--b-cut=-2"], 300, env=child_env())
    assert res.returncode == 0, res.stderr
    res = run_bounded([*analysis, "report", summary], 300, env=child_env())
    assert res.returncode == 0, res.stderr
    print(res.stdout)
    assert "alpha = 2.5, sigma = 0.01" in res.stdout
    events, _, _ = reader.read(d / "serial.h5")
    row = {line.split()[0]: line.split()[1] for line in res.stdout.splitlines()
           if line.strip().startswith(("events", "frac(mu>=mu_c)"))}
    assert int(row["events"]) == 6000
    assert float(row["frac(mu>=mu_c)"]) == pytest.approx(np.mean(events["mu"] >= -1), abs=1e-4)


def test_default_law_is_aging_and_unchanged(tmp_path):
    """A config without model.law runs the aging law, stores law = "aging", and is the same config as
    with law = "aging" written out (so it runs the same events: a run is a function of its config)."""
    base = '[model]\nN = 40\n{law}b = 20.0\n\n[run]\nevents = 40\ntransient = 10\nseeds = 1\n\n' \
           '[integrator]\nmethod = "ark4"\n'
    default = tmp_path / "default.toml"
    default.write_text(base.format(law=""))
    assert loads(base.format(law="")) == loads(base.format(law='law = "aging"\n'))
    res = run_cli("run", default, "-o", default.with_suffix(".h5"))
    assert res.returncode == 0, res.stderr
    _, tasks, attrs = reader.read(default.with_suffix(".h5"))
    assert list(tasks["law"]) == ["aging"] and 'law = "aging"' in attrs["config"]
    stored = loads(attrs["config"]).model
    assert (stored.law, stored.a, stored.b, stored.c, stored.alpha, stored.sigma) == ("aging", 0.0, 20.0, 1000.0,
                                                                                      None, None)
    assert tasks["b"][0] == 20.0 and np.isnan(tasks["alpha"][0]) and np.isnan(tasks["sigma"][0])
    assert Model().law == laws.DEFAULT == "aging"
