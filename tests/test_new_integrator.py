"""Adding an event integrator is its scheme and stepper plus one registry entry (ensemble/model/methods.py).

A copy of the package gets one new module, ensemble/model/heun.py: Heun's method with Euler's as its
embedded one (2(1)), every stage explicit, written against the steppers' contract (steppers.py) as
exp4's stepper is; and one entry in METHODS with its import. Nothing else is edited: the copy
validates the method (its description is derived from the registry), compiles it into the law's kernels
beside the others, and runs a chain whose events are those of ark4 at a tight tolerance.

Slow by nature (the slower tier, `make slow`, which CI runs): the copy's kernels compile, about a minute
and a half.
"""
import sys

import numpy as np
import pytest

from ensemble.store import reader

from .processes import package_copy, run_bounded

HEUN = '''"""Heun's method with Euler's embedded (2(1)), every stage explicit (a test's integrator)."""
from typing import NamedTuple

import numba as nb
import numpy as np

from .laws import has_state
from .steppers import NO_SUMS, _error_norms, stage_columns
from .workspace import ARK_A, ARK_G, ARK_V, K1V, P, P0, PS, V, V0, VS, Y, Y0, YS


class HeunEuler(NamedTuple):
    name: str = "Heun-Euler 2(1)"
    c: tuple = (0.0, 1.0)
    embedded_order: int = 1
    kind = "adaptive explicit"

    def stepper(self):
        return heun_step

    def error_weights(self):
        return np.array([-0.5, 0.5])      # b - bhat = (1/2, 1/2) - (1, 0)

    def refusal(self, law):
        return None


@nb.njit(error_model="numpy")
def heun_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    state = has_state(p.law)
    for k in range(na):
        i = act[k]
        W[i, YS] = W[i, Y0]
        W[i, VS] = W[i, V0]
        W[i, PS] = W[i, P0]
    pw, ys = stage_columns(W, act, na, n, tau, p, yrest, 0, 0.5, True, state, 0.0, 0.0)
    for k in range(na):
        i = act[k]
        W[i, YS] = W[i, Y0] + h * W[i, ARK_V]
        W[i, VS] = W[i, V0] + h * W[i, ARK_A]
        if state:
            W[i, PS] = W[i, P0] + h * W[i, ARK_G]
    pw, ys = stage_columns(W, act, na, n, tau + h, p, yrest, 1, 0.5, True, state, pw, ys)
    err = 0.0
    for k in range(na):
        i = act[k]
        W[i, K1V] = W[i, ARK_A]
        W[i, Y] = W[i, Y0] + 0.5 * h * (W[i, ARK_V] + W[i, ARK_V + 1])
        W[i, V] = W[i, V0] + 0.5 * h * (W[i, ARK_A] + W[i, ARK_A + 1])
        dp = 0.0
        if state:
            W[i, P] = W[i, P0] + 0.5 * h * (W[i, ARK_G] + W[i, ARK_G + 1])
            dp = 0.5 * h * (W[i, ARK_G + 1] - W[i, ARK_G])
        W[i, YS] = W[i, Y]
        e1, e2, e3 = _error_norms(W, i, 0.5 * h * (W[i, ARK_V + 1] - W[i, ARK_V]),
                                  0.5 * h * (W[i, ARK_A + 1] - W[i, ARK_A]), dp, p.rtol, p.atol)
        err = max(err, e1, e2, e3)
    return pw * h, ys * h, err, NO_SUMS, NO_SUMS
'''

ENTRY = ('    Method("heun", HeunEuler(), "Heun\'s method with Euler\'s embedded: second order, every stage '
         'explicit"),\n')
IMPORT = "from .heun import HeunEuler\n"

# one event of a 12-block chain from the same onset, with Heun at two tolerances and ark4 far below both: Heun's
# step control is that of an embedded order 1 (steps ~ rtol^(-1/2): 10x for 100x tighter; ark4's 3.1x, ark3's 4.1x)
EVENT = """
import numpy as np
from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event
model = Model(N=12)
force, psi = -np.random.default_rng(3).uniform(0, 1, 12), np.zeros(12)
epicenter, _, force, psi = advance_to_onset(force, psi, model)
for method, rtol in (("heun", 1e-6), ("heun", 1e-8), ("ark4", 1e-12)):
    r = check(run_event(force, psi, epicenter, model, Integrator(method=method, rtol=rtol)))
    print(r.steps, repr(float(r.slip)), repr(float(r.relative_energy_residual)), np.count_nonzero(r.profile))
"""

CONFIG = """[model]
N = 12
b = 20.0

[run]
seeds = 1
events = 40
transient = 0

[integrator]
method = "{method}"
rtol = {rtol}
"""


def ensemble(root, env, *args):
    return run_bounded([sys.executable, "-m", "ensemble", *map(str, args)], 600, cwd=root, env=env)


@pytest.fixture(scope="module")
def copy_with_heun(tmp_path_factory):
    """A copy of the package with heun.py; the registry's entry is the test's to add."""
    root = tmp_path_factory.mktemp("heun")
    env = package_copy(root, "ensemble", own_cache=True)
    (root / "ensemble/model/heun.py").write_text(HEUN)
    (root / "heun.toml").write_text(CONFIG.format(method="heun", rtol=1e-9))
    (root / "ark4.toml").write_text(CONFIG.format(method="ark4", rtol=1e-11))
    return root, env


def add_entry(root):
    methods = root / "ensemble/model/methods.py"
    text = methods.read_text()
    registry_end = ")}\n\n\n@functools.cache"
    imports_end = "from .workspace import ARK_STAGES\n"
    assert text.count(registry_end) == 1 and text.count(imports_end) == 1
    methods.write_text(text.replace(imports_end, imports_end + IMPORT).replace(registry_end, ENTRY + registry_end))


@pytest.mark.slow
def test_an_integrator_by_its_stepper_and_one_entry_validates_and_runs_ark4s_events(copy_with_heun):
    root, env = copy_with_heun
    res = ensemble(root, env, "validate", "heun.toml")        # the stepper alone is not a method
    assert res.returncode == 2 and "integrator.method must be one of" in res.stderr, res.stderr
    add_entry(root)
    res = ensemble(root, env, "validate", "heun.toml")
    assert res.returncode == 0, res.stderr
    assert 'method = "heun"' in res.stdout
    res = run_bounded([sys.executable, "-c", "import ensemble, ensemble.integrators as i; print(ensemble.__file__); "
                       "print(i.KEYS['method'].meaning); print(i.INTEGRATORS['heun'].stages)"], 60, cwd="/", env=env)
    path, meaning, stages = res.stdout.strip().splitlines()
    assert path == str(root / "ensemble/__init__.py")                 # the copy, not this tree
    assert "heun (adaptive explicit)" in meaning and stages == "2"    # derived from the entry
    res = run_bounded([sys.executable, "-c", EVENT], 300, cwd="/", env=env)
    assert res.returncode == 0, res.stderr
    (loose, *_), (tight, slip, residual, slipped), (_, reference, *_) = [
        [float(x) for x in line.split()] for line in res.stdout.splitlines()]
    assert slipped == 12 and 7 < tight / loose < 14, (loose, tight)    # second order, and its own stepper
    assert abs(slip / reference - 1) < 1e-7 and residual < 1e-8
    for method in ("heun", "ark4"):
        res = ensemble(root, env, "run", f"{method}.toml", "-o", f"{method}.h5")
        assert res.returncode == 0, res.stderr
    heun, _, attrs = reader.read(root / "heun.h5")
    ark4, _, _ = reader.read(root / "ark4.h5")
    assert 'method = "heun"' in attrs["config"]                        # the catalog records it
    assert len(heun["t"]) == len(ark4["t"]) == 40
    # the same chain from the same seed: the first events are ark4's to the tolerances (a chaotic chain
    # parts later)
    first = slice(0, 10)
    assert np.array_equal(heun["epicenter"][first], ark4["epicenter"][first])
    assert np.array_equal(heun["n_slipped"][first], ark4["n_slipped"][first])
    assert heun["n_slipped"][first].max() > 1                          # events of several blocks
    np.testing.assert_allclose(heun["slip"][first], ark4["slip"][first], rtol=1e-5)
    np.testing.assert_allclose(heun["t"][first], ark4["t"][first], rtol=1e-6)
