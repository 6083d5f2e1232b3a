"""NaN and inf end in the status NONFINITE, never in an index out of bounds (heap corruption).

numba does not check indices unless compiled with NUMBA_BOUNDSCHECK=1, so a block index
computed from a NaN (the onset tree used to descend into its padding) would write past the
work arrays silently. The last test runs the hard cases and the bad inputs in one subprocess
compiled with bounds checks, in its own numba cache (the checked build must not replace the
normal one).

No tolerances: statuses and block indices are exact.
"""
import json
import math
import os
import sys

import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.integrators import INTEGRATORS, kernel_params
from ensemble.model.chain import simulate
from ensemble.model.onset import onset_delay
from ensemble.model.schedule import tree_min, tree_set
from ensemble.model.workspace import NDIAG, NONFINITE, OK, UNLIMITED, Workspace, tree_size

from .processes import ROOT, run_bounded


def test_tree_min_returns_a_block_whatever_the_keys():
    """NaN keys (unordered) must not lead the descent into the padding leaves past N."""
    rng = np.random.default_rng(1)
    for n in (1, 3, 60, 100):
        for pattern in range(20):
            tree = np.full(tree_size(n), np.inf)
            for i in range(n):
                tree_set(tree, i, math.nan if rng.random() < 0.3 or pattern == 0 else rng.normal())
            _, block = tree_min(tree)
            assert 0 <= block < n


def test_onset_delay_with_b_over_nu_beyond_float64():
    """ln(b / nu) taken from b / nu = inf made the delay NaN; it is inf (never), as it should be."""
    assert onset_delay(-1.0, 0.0, 1e-20, 1e300) == math.inf


def run_simulate(model, force, psi, events=5, method="rk4"):
    ws = Workspace(model.N)
    ws.load(force, psi)
    t, epi, diag = np.empty(events), np.empty(events, dtype=np.int64), np.empty((events, NDIAG))
    params = kernel_params(model, Integrator(method=method))
    return simulate(ws.arrays, np.zeros(2), params, events, UNLIMITED, t, epi, diag)


def test_nonfinite_parameters_are_named():
    """Checked before anything runs: atol = inf, for one, would otherwise run on without error control."""
    model = Model(N=30)
    force, psi = -np.linspace(0.0, 1.0, model.N), np.zeros(model.N)
    ws = Workspace(model.N)
    params = kernel_params(model, Integrator())
    cl = kernel_params(Model(N=30, law="carlson-langer"), Integrator())
    for base, bad in ((params, {"l2": math.nan}), (params, {"nu": math.inf}), (params, {"atol": math.inf}),
                      (params, {"max_step": math.nan}), (params, {"max_duration": math.nan}),
                      (params, {"law": params.law._replace(b=math.nan)}),      # a friction law's own keys too
                      (cl, {"law": cl.law._replace(alpha=math.inf)})):
        ws.load(force, psi)
        out = np.empty(3), np.empty(3, dtype=np.int64), np.empty((3, NDIAG))
        assert simulate(ws.arrays, np.zeros(2), base._replace(**bad), 3, UNLIMITED, *out) == (NONFINITE, 0), bad
    # the two bounds may be inf: none
    ws.load(force, psi)
    out = np.empty(3), np.empty(3, dtype=np.int64), np.empty((3, NDIAG))
    unbounded = params._replace(max_step=math.inf, max_duration=math.inf)
    assert simulate(ws.arrays, np.zeros(2), unbounded, 3, UNLIMITED, *out) == (OK, 3)


# Runs in a subprocess compiled with NUMBA_BOUNDSCHECK=1; prints one JSON line
# {"hard": {case: "ok" or the error}, "bad": {input: status code or the error}}.
BOUNDSCHECK_SCRIPT = r"""
import dataclasses, json, math, os
import numpy as np
from ensemble.config import Config, Integrator, Model, Run
from ensemble.run.trajectory import SimulationError, Trajectory
from ensemble.sweep import task_list
from tests.test_hard_cases import CASES
from tests.test_nonfinite import run_simulate

METHODS = json.loads(os.environ["BOUNDSCHECK_METHODS"])
hard, bad = {}, {}
for name, (model, rk4_dt, _) in CASES.items():
    model = dataclasses.replace(model, N=min(model.N, 30))
    for method in METHODS:
        for budget in (None, 50):     # whole events, and events paused every ~50 block-steps
            integ = Integrator(method="rk4", dt=rk4_dt) if method == "rk4" else Integrator(method=method)
            cfg = Config(model=model, run=Run(), integrator=integ)
            traj = Trajectory(cfg, task_list(cfg)[0])
            key = f"{name} [{method}{'' if budget is None else ', budget 50'}]"
            try:
                if budget is None:
                    traj.advance(10)
                else:
                    while traj.done < 10:
                        traj.advance(10 - traj.done, budget)
                hard[key] = "ok"
            except (IndexError, SimulationError) as err:
                hard[key] = type(err).__name__ + ": " + str(err)

def initial(model):
    return -np.random.default_rng(0).random(model.N), np.zeros(model.N)

model = Model(N=30)
for name, block, column, value in (("NaN force", 7, 0, math.nan), ("-inf force", 20, 0, -math.inf),
                                   ("inf psi", 5, 1, math.inf), ("NaN psi", 29, 1, math.nan)):
    state = initial(model)
    state[column][block] = value
    for method in METHODS:
        try:
            bad[f"{name} [{method}]"] = int(run_simulate(model, *state, method=method)[0])
        except IndexError as err:
            bad[f"{name} [{method}]"] = "IndexError: " + str(err)
huge = Model(N=30, b=1e300, nu=1e-20)
try:
    bad["b = 1e300, nu = 1e-20"] = int(run_simulate(huge, *initial(huge), method=METHODS[0])[0])
except IndexError as err:
    bad["b = 1e300, nu = 1e-20"] = "IndexError: " + str(err)
print(json.dumps({"hard": hard, "bad": bad}))
"""


@pytest.mark.slow
def test_bounds_checked_hard_cases_and_bad_inputs(tmp_path):
    """Hard cases (small N, with and without pauses) run; NaN/inf inputs give NONFINITE, with every method.
    Most of the time is the bounds-checked compilation of the aging law's kernels, about a minute here: one
    compilation holds every method (model/methods.py). Slow by nature: the slower tier, `make slow`."""
    methods = tuple(INTEGRATORS)
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp_path / "numba"),
               PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1",
               BOUNDSCHECK_METHODS=json.dumps(list(methods)))
    res = run_bounded([sys.executable, "-c", BOUNDSCHECK_SCRIPT], 600, cwd=ROOT, env=env)
    assert res.returncode == 0, res.stderr
    outcome = json.loads(res.stdout.strip().splitlines()[-1])
    for kind in ("hard", "bad"):
        print("\n".join(f"{kind}: {k}: {v}" for k, v in outcome[kind].items()))
    assert len(outcome["hard"]) == 7 * 2 * len(methods) and len(outcome["bad"]) == 4 * len(methods) + 1
    assert outcome["hard"] == {key: "ok" for key in outcome["hard"]}
    assert outcome["bad"] == {key: NONFINITE for key in outcome["bad"]}
