"""The lattice (ensemble/model/geometry/lattice.py) in the kernels: a lattice of one row is the chain bit for bit,
and a plane's sequence of events agrees with a plain integration of the whole lattice (tests/reference.py: RK4 on
every block in physical variables, every stick and onset located by bisecting the step; it shares no code with
ensemble/).

The plane here is 6 x 5 blocks with different springs along (l = 2) and across strike (l_y = 1.5), so a spring
missing or swapped across strike changes every event; at b = 20 no block is stiffer than its weakening (the
stiffest, 1 + 2 l^2 + 2 l_y^2 = 13.5), so nothing creeps and the reference's inertial equations are the model's.
nu = 1e-2 makes the loading periods short enough to integrate.
"""
import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.geometry.lattice import LatticeParams
from ensemble.model.workspace import (D_DURATION, D_FIRST, D_KIND, D_LAST, D_NSLIP, D_SLIP, KIND_CREEP, NDIAG, OK,
                                     UNLIMITED, Workspace)

from .reference import displacements_for, reference_sequence

NX, NY = 6, 5
PLANE = {"l": 2.0, "nu": 1e-2, "a": 1.0, "b": 20.0, "c": 1000.0}
L_Y = 1.5
EVENTS = 11        # events of the sequence integrated by both
SEED = 5

# method: ([integrator], events compared, relative tolerance of the first event's onset time and slip, absolute
# tolerance of the durations); event k's tolerance is the first one's times 10^(k/2), the chaotic growth of a
# difference (tests/test_sequences.py measured it on the chain). Measured (onset time, slip; duration) over the
# 11 events: rk4 at most 2.0e-10, 2.9e-9 (event 10; 4.6e-10 before it); 4.9e-6; ark4 at rtol 1e-5 3.8e-6, 5.4e-5
# (event 10; 6.5e-6 before); 0.11. The 12th event's epicenter differs with ark4 (chaos).
METHODS = {"rk4": ({"method": "rk4", "dt": 1e-3}, 11, 1e-10, 1e-5),
           "ark4": ({"method": "ark4", "rtol": 1e-5}, 11, 1e-6, 0.5)}
REF_DT, ALPHA = 1e-3, 0.01


def lattice_params(model, integrator, nx, ny, l_y):
    """The kernels' record with the lattice nx x ny as its geometry."""
    p = kernel_params(model, Integrator(**integrator))
    return p._replace(geom=LatticeParams(nx, ny, float(model.l) ** 2, float(l_y) ** 2))


def run_kernels(params, force, events):
    """(status, onsets, epicenters, diagnostics) of `events` events from the c-free forces `force`, theta = 1, t = 0."""
    n = len(force)
    ws = Workspace(n)
    ws.load(force, np.zeros(n))
    clock = np.zeros(2)
    t, epi, diag = np.empty(events), np.empty(events, dtype=np.int64), np.empty((events, NDIAG))
    status, k = simulate(ws.arrays, clock, params, events, UNLIMITED, t, epi, diag)
    return status, t[:k], epi[:k], diag[:k]


def initial_forces(n, seed=SEED):
    return -np.random.default_rng(seed).random(n)


@pytest.mark.parametrize("b", [20.0, 15.0])
def test_one_row_is_the_chain_bit_for_bit(b):
    """The lattice of N x 1 gives the chain's catalog: every onset, epicenter and diagnostic, bit for bit; at
    b = 15 through the creep phase (creep episodes and the events that take them over)."""
    model = Model(N=60, b=b)
    integrator = {"method": "exp4"}
    chain = run_kernels(kernel_params(model, Integrator(**integrator)), initial_forces(60), 150)
    row = run_kernels(lattice_params(model, integrator, 60, 1, 2.5), initial_forces(60), 150)
    assert chain[0] == row[0] == OK
    for name, ours, theirs in zip(("onsets", "epicenters", "diagnostics"), row[1:], chain[1:]):
        np.testing.assert_array_equal(ours, theirs, err_msg=name)
    creep = (chain[3][:, D_KIND] == KIND_CREEP).sum()
    assert creep > 20 if b == 15.0 else creep == 0, f"{creep} creep episodes"


@pytest.fixture(scope="module")
def reference():
    """The plain integration's first EVENTS events of the plane from the test's initial state."""
    model = Model(N=NX, **PLANE)
    force = initial_forces(NX * NY)
    u = displacements_for(force, 0.0, model, nx=NX, l_y=L_Y)
    return reference_sequence(u, np.ones(NX * NY), 0.0, EVENTS, **PLANE, dt=REF_DT, alpha=ALPHA, nx=NX, l_y=L_Y)


@pytest.mark.parametrize("method", METHODS)
def test_plane_sequence_agrees_with_the_plain_integration(reference, method):
    """Epicenter, the slipped blocks' extent along strike and their number, onset time, slip and duration of the
    plane's first events (each block on the loader, its four neighbours or fewer at an edge)."""
    integrator, n, tol0, dur_atol = METHODS[method]
    status, t, epi, diag = run_kernels(lattice_params(Model(N=NX, **PLANE), integrator, NX, NY, L_Y),
                                       initial_forces(NX * NY), n)
    assert status == OK and len(t) == n
    slipped = reference["profile"][:n] > 0.0
    x = np.arange(NX * NY) % NX
    np.testing.assert_array_equal(epi, reference["epicenter"][:n])
    np.testing.assert_array_equal(diag[:, D_NSLIP], slipped.sum(axis=1))
    np.testing.assert_array_equal(diag[:, D_FIRST], [x[s].min() for s in slipped])
    np.testing.assert_array_equal(diag[:, D_LAST], [x[s].max() for s in slipped])
    rtol = tol0 * 10 ** (np.arange(n) / 2)
    assert np.all(np.abs(t / reference["t"][:n] - 1) <= rtol), np.abs(t / reference["t"][:n] - 1)
    assert np.all(np.abs(diag[:, D_SLIP] / reference["slip"][:n] - 1) <= rtol)
    assert np.all(np.abs(diag[:, D_DURATION] - reference["duration"][:n]) <= dur_atol)
    # the sequence has events of every kind: one block, the whole plane, between
    assert slipped.sum(axis=1).min() == 1 and slipped.sum(axis=1).max() == NX * NY
