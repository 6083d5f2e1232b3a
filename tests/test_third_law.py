"""Adding a friction law touches one file (docs/laws.md, "Adding a friction law").

A copy of the package gets one new module, ensemble/model/laws/coulomb.py: static threshold 1,
constant dynamic friction 1 - drop, no state, the loader still during events. Nothing else is
edited; the copy then validates, runs, records and reports the law. The law has an exact answer:
a block that slides alone from its threshold oscillates about its new equilibrium and stops after
half a period, having slipped 2 drop / k (k = 1 + 2 l^2 inside the chain, 1 + l^2 at an end).

Slow by nature (the slower tier, `make slow`, which CI runs): the copy's kernels compile for the new law,
about a minute and a half.
"""
import sys

import numpy as np
import pytest

from ensemble.store import reader

from .processes import package_copy, run_bounded

COULOMB = '''"""Coulomb friction: static threshold 1, dynamic 1 - drop, no state (a test's third law)."""
from collections import namedtuple
import math

import numba as nb

from . import Key, Law, Scales

CoulombParams = namedtuple("CoulombParams", "drop")


@nb.njit(cache=True, inline="always")
def friction(law, v, psi):
    return 1.0 - law.drop


@nb.njit(cache=True, inline="always")
def threshold(law, psi):
    return 1.0


@nb.njit(cache=True, inline="always")
def state_rate(law, v, psi):
    return 0.0


@nb.njit(cache=True, inline="always")
def rest_state(law, psi, dt):
    return psi


@nb.njit(cache=True, inline="always")
def onset_delay(law, force, psi, nu):
    return 0.0 if force >= 1.0 else (1.0 - force) / nu


@nb.njit(cache=True, inline="always")
def implicit_state(law, W, act, na, hg):
    """No state."""


@nb.njit(cache=True, inline="always")
def stiff_limit(law, rate_limit):
    return -math.inf


@nb.njit(cache=True, inline="always")
def rk4_unstable(law, v, psi, rate_limit, state_limit):
    return False


LAW = Law(
    name="coulomb", params=CoulombParams,
    keys={"drop": Key(0.05, "model force", lambda x: 0 < x < 1, "in (0, 1)", "static minus dynamic friction")},
    convention="Coulomb friction: static 1, dynamic 1 - drop; the loader stands still during events",
    has_state=False, loader_moves=False, friction=friction, threshold=threshold, state_rate=state_rate,
    rest_state=rest_state, onset_delay=onset_delay, implicit_state=implicit_state, stiff_limit=stiff_limit,
    rk4_unstable=rk4_unstable, scales=Scales(mu_bins="-4:0:40", mu_c=-1.0, b_cut=-2.0, tnu_bins="0:4:80"))
'''


@pytest.fixture(scope="module")
def copy_with_a_third_law(tmp_path_factory):
    root = tmp_path_factory.mktemp("third_law")
    env = package_copy(root, "ensemble", own_cache=True)
    (root / "ensemble/model/laws/coulomb.py").write_text(COULOMB)
    (root / "cfg.toml").write_text('[model]\nN = 40\nl = 3.0\nnu = 0.01\nlaw = "coulomb"\ndrop = 0.05\n\n'
                                   '[run]\nseeds = 2\nevents = 400\ntransient = 100\n\n'
                                   '[integrator]\nmethod = "ark4"\nrtol = 1e-8\n')
    return root, env


def ensemble(root, env, *args):
    return run_bounded([sys.executable, "-m", "ensemble", *map(str, args)], 600, cwd=root, env=env)


@pytest.mark.slow
def test_a_law_in_one_new_module_validates_runs_and_is_recorded(copy_with_a_third_law):
    root, env = copy_with_a_third_law
    res = run_bounded([sys.executable, "-c", "import ensemble; print(ensemble.__file__)"], 60, cwd="/", env=env)
    assert res.stdout.strip() == str(root / "ensemble/__init__.py")       # the copy, not this tree
    res = ensemble(root, env, "validate", "cfg.toml")
    assert res.returncode == 0, res.stderr
    assert "coulomb" in res.stdout and "drop" in res.stdout
    res = ensemble(root, env, "run", "cfg.toml", "--set", "model.alpha=2")
    assert res.returncode == 2 and "model.alpha does not belong to model.law = 'coulomb'" in res.stderr
    res = ensemble(root, env, "run", "cfg.toml", "-o", "c.h5")
    assert res.returncode == 0, res.stderr
    events, tasks, _ = reader.read(root / "c.h5")
    assert list(tasks["law"]) == ["coulomb", "coulomb"]
    assert np.all(np.isnan(tasks["b"])) and list(tasks["drop"]) == [0.05, 0.05]   # the new law's column
    assert len(events["t"]) == 800
    res = ensemble(root, env, "status", "c.h5")
    assert res.returncode == 0 and "drop" in res.stdout, res.stdout + res.stderr
    # the exact slip of a block that slides alone: 2 drop / k
    alone = events["n_slipped"] == 1
    inner = alone & (events["epicenter"] > 0) & (events["epicenter"] < 39)
    end = alone & ~inner
    assert inner.sum() > 20 and end.sum() > 0
    np.testing.assert_allclose(events["slip"][inner], 2 * 0.05 / (1 + 2 * 9.0), rtol=1e-5)
    np.testing.assert_allclose(events["slip"][end], 2 * 0.05 / (1 + 9.0), rtol=1e-5)
