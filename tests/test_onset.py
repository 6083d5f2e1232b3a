"""Quiet loading: the analytic onset time against brute force and force balance."""
import math

import numpy as np
import pytest

from ensemble.config import Model
from ensemble.events import advance_to_onset
from ensemble.model.onset import grow_state, onset_delay, solve_y_minus_log_y


@pytest.mark.parametrize("L", [1.0 + 1e-12, 1.0 + 1e-6, 1.01, 1.5, 3.0, 25.0, 1e3, 1e8])
def test_lambert_root_on_upper_branch(L):
    y = solve_y_minus_log_y(L)
    print(f"L = {L}: residual {abs(y - math.log(y) - L) / L:.1e} L")
    assert y >= 1.0
    # measured 0 at every L (the residual rounds away): 1e-14 L leaves a few dozen ulps
    assert abs(y - math.log(y) - L) <= 1e-14 * L


@pytest.mark.parametrize("nu,b", [(1e-8, 20.0), (1e-8, 50.0), (1e-3, 30.0), (1e-12, 20.0)])
def test_onset_delay_matches_brute_force(nu, b):
    """The delay is the first time F + nu t reaches b ln(theta + t), on a log-spaced scan."""
    rng = np.random.default_rng(3)
    imbalance, before, after = [], [], []
    for _ in range(200):
        psi = rng.uniform(-9.0, 25.0)          # theta from 1e-4 to 7e10
        F = b * psi - rng.uniform(1e-6, 300.0)  # below threshold
        d = onset_delay(F, psi, nu, b)
        theta = math.exp(psi)
        # force balance at the root, relative to the size of its terms
        imbalance.append(abs(F + nu * d - b * math.log(theta + d)) / max(1.0, abs(b * psi), nu * d))
        # the largest excess force before the root (a scan up to 1e-9 d before it), relative
        t = np.concatenate([[0.0], np.geomspace(1e-12, 1.0, 4000) * d * (1 - 1e-9)])
        before.append(np.max(F + nu * t - b * np.log(theta + t)) / max(1.0, abs(b * psi)))
        # the excess just after it
        after.append(F + nu * d * 1.001 - b * math.log(theta + d * 1.001))
    print(f"nu {nu}, b {b}: largest force imbalance at the root {max(imbalance):.1e}, largest excess "
          f"before it {max(before):.1e} (of the scale), smallest excess 0.1% after it {min(after):.1e}")
    # measured up to 1.1e-11 (nu = 1e-3, where nu * d is large), 6.4e-16 otherwise
    assert max(imbalance) <= 1e-9
    # no earlier crossing: measured at most -7.9e-12 .. -3.6e-10 (always negative, largest at the
    # scan's last point); the bound admits round-off there, not a crossing
    assert max(before) < 1e-9
    # and positive just after it: measured at least 3.7e-3
    assert min(after) > 0


def test_block_at_threshold_starts_now():
    assert onset_delay(20.0 * 3.0, 3.0, 1e-8, 20.0) == 0.0
    assert onset_delay(20.0 * 3.0 + 1.0, 3.0, 1e-8, 20.0) == 0.0


def test_state_growth_is_exact():
    for psi, dt in [(-9.0, 1e-6), (0.0, 5.0), (25.0, 1e10), (-5.0, 1e12)]:
        print(f"psi {psi}, dt {dt}: relative error {math.exp(grow_state(psi, dt)) / (math.exp(psi) + dt) - 1:.1e}")
        # measured at most 6.7e-16 (round-off of exp and log1p)
        assert math.isclose(math.exp(grow_state(psi, dt)), math.exp(psi) + dt, rel_tol=1e-13)


def test_fast_forward_lands_on_threshold_of_epicenter_only():
    """After the jump the epicenter's force equals its static threshold; every other block is below."""
    model = Model(N=300, b=20.0)
    rng = np.random.default_rng(7)
    psi = rng.uniform(5.0, 20.0, model.N)
    force = model.b * psi - rng.uniform(0.1, 50.0, model.N)
    epicenter, delay, f, p = advance_to_onset(force, psi, model)
    assert delay > 0
    excess = f - model.b * p
    print(f"epicenter's excess over its threshold {excess[epicenter] / (model.b * p[epicenter]):.1e} of it; "
          f"largest other {np.max(np.delete(excess, epicenter)):.2e}")
    # measured 1.3e-16 of the threshold (the root is solved to round-off)
    assert abs(excess[epicenter]) <= 1e-12 * model.b * p[epicenter]
    others = np.delete(excess, epicenter)
    assert np.all(others < 0)
    # brute force: every block's own onset is later than the epicenter's
    delays = [onset_delay(force[i], psi[i], model.nu, model.b) for i in range(model.N)]
    assert int(np.argmin(delays)) == epicenter
