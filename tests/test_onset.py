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
    assert y >= 1.0
    assert abs(y - math.log(y) - L) <= 1e-12 * L


@pytest.mark.parametrize("nu,b", [(1e-8, 20.0), (1e-8, 50.0), (1e-3, 30.0), (1e-12, 20.0)])
def test_onset_delay_matches_brute_force(nu, b):
    """The delay is the first time F + nu t reaches b ln(theta + t), on a log-spaced scan."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        psi = rng.uniform(-9.0, 25.0)          # theta from 1e-4 to 7e10
        F = b * psi - rng.uniform(1e-6, 300.0)  # below threshold
        d = onset_delay(F, psi, nu, b)
        theta = math.exp(psi)
        # force balance at the root
        assert abs(F + nu * d - b * math.log(theta + d)) <= 1e-9 * max(1.0, abs(b * psi), nu * d)
        # no earlier crossing: the excess force is negative everywhere before the root
        t = np.concatenate([[0.0], np.geomspace(1e-12, 1.0, 4000) * d * (1 - 1e-9)])
        excess = F + nu * t - b * np.log(theta + t)
        assert np.all(excess < 1e-9 * max(1.0, abs(b * psi)))
        # and positive just after it
        assert F + nu * d * 1.001 - b * math.log(theta + d * 1.001) > 0


def test_block_at_threshold_starts_now():
    assert onset_delay(20.0 * 3.0, 3.0, 1e-8, 20.0) == 0.0
    assert onset_delay(20.0 * 3.0 + 1.0, 3.0, 1e-8, 20.0) == 0.0


def test_state_growth_is_exact():
    for psi, dt in [(-9.0, 1e-6), (0.0, 5.0), (25.0, 1e10), (-5.0, 1e12)]:
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
    assert abs(excess[epicenter]) <= 1e-9 * model.b * p[epicenter]
    others = np.delete(excess, epicenter)
    assert np.all(others < 0)
    # brute force: every block's own onset is later than the epicenter's
    delays = [onset_delay(force[i], psi[i], model.nu, model.b) for i in range(model.N)]
    assert int(np.argmin(delays)) == epicenter
