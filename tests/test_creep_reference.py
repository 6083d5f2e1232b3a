"""The quasi-static creep equations (docs/numerics.md, "Quasi-static creep") against the full inertial
equations of a few blocks, solved independently by scipy (tests/creep_reference.py): the derivation,
its stability criterion and the single-block creep at the plate rate."""
import numpy as np
import pytest

from .creep_reference import (cluster_matrix, inertial, inertial_rhs, jacobian, on_the_manifold,
                              quasi_static_velocity, stiffness)

L = 3.0


def deviation_from_quasi_static(nu, b=5.0, creeping=(1, 2, 3), n=5):
    """Largest relative difference between the inertial and the quasi-static velocities of a creeping
    cluster over 3 / nu time units (its state psi relaxes by about one)."""
    K = stiffness(n, L)
    C = list(creeping)
    u, v, psi = on_the_manifold(K, C, b, nu, np.log(b / nu) + np.array([1.0, 1.5, 1.0])[:len(C)],
                                np.zeros(n - len(C)))
    t_end = 3.0 / nu
    t, _, vc, pc, rest_force = inertial(K, C, 0.0, b, nu, u, v, psi, t_end, np.linspace(0, t_end, 25))
    assert np.all(rest_force < b * np.delete(psi, C)), "a neighbour held at rest would have started"
    worst = 0.0
    for k in range(len(t)):
        full = psi.copy()
        full[C] = pc[k]
        worst = max(worst, np.max(np.abs(vc[k] / quasi_static_velocity(K, C, b, nu, full) - 1)))
    # the velocities change by a factor of about 2 over the run: the comparison is not trivial
    assert vc[-1, 1] < 0.6 * vc[0, 1]
    return worst


def test_a_creeping_cluster_follows_the_quasi_static_velocities():
    """(K_C - b I) v = nu - b exp(-psi) holds along the full dynamics up to the inertia it neglects,
    which shrinks with the creep's rate (about nu here): 3x slower creep, about 3x closer (at the paper's
    nu = 1e-8 the neglected inertia is of relative order 1e-8)."""
    fast, slow = deviation_from_quasi_static(1e-2), deviation_from_quasi_static(3e-3)
    assert fast < 1e-2 and slow < 3e-3, (fast, slow)
    assert fast / slow > 2, (fast, slow)


@pytest.mark.parametrize("creeping", [(2,), (1, 2), (1, 2, 3), (0, 1)])
def test_quasi_static_creep_is_stable_exactly_while_its_matrix_is_positive_definite(creeping):
    """Linearised full dynamics on the quasi-static manifold (nu = 1e-8): nothing grows faster than about
    the loading's rate while K_C - b I is positive definite (a = 0's slow inertial growth: next test); a mode
    grows at sqrt(-lambda_min) once it is not, on the inertial time scale: the switch to an event."""
    K = stiffness(5, L)
    C = list(creeping)
    nu = 1e-8
    for b in (2.0, 5.0, 8.0, 12.0, 15.0, 18.0):
        lam = np.linalg.eigvalsh(cluster_matrix(K, C, b))[0]
        psi_c = np.full(len(C), np.log(b / nu) + 2.0)
        u, v, psi = on_the_manifold(K, C, b, nu, psi_c, np.zeros(5 - len(C)))
        rhs = inertial_rhs(K, C, 0.0, b, nu, np.delete(u, C))
        growth = np.max(np.linalg.eigvals(jacobian(rhs, 0.0, np.concatenate([u[C], v[C], psi[C]]))).real)
        if lam > 0:
            assert growth < 1e-6, (C, b, lam, growth)
        else:
            assert growth == pytest.approx(np.sqrt(-lam), rel=0.05), (C, b, lam, growth)


def _steady_single_block(a, b, nu):
    """N = 1 in steady sliding at the plate rate: v = nu, theta = 1 / nu, force balance; (K, u, v, psi)."""
    K = stiffness(1, L)
    psi = np.array([-np.log(nu)])
    u = np.array([-(b * psi[0] + a * np.log1p(nu))])     # nu * 0 - u = friction
    return K, u, np.array([nu]), psi


def test_a_single_block_below_the_loader_stiffness_creeps_at_the_plate_rate_only_with_a():
    """N = 1, b = 0.5 below its only spring, the loader's (1). Quasi-statically it creeps at v = nu
    (K - b I > 0). With inertia and a = 0 the steady creep is not stable (Rice & Ruina 1983: inertia raises
    the critical stiffness without bound as a -> 0): the linearisation has a slow decaying mode
    -nu / (1 - b) and an inertial oscillation sqrt(1 - b) that grows at nu b / (2 (1 - b)), a rate of the
    order of the loading's, which the creep phase, without inertia, does not have. With a = 0.1 it decays,
    and the full solution settles to v = nu, theta = 1 / nu."""
    nu, b = 1e-2, 0.5
    K, u, v, psi = _steady_single_block(0.0, b, nu)
    modes = np.linalg.eigvals(jacobian(inertial_rhs(K, [0], 0.0, b, nu, np.zeros(0)), 0.0,
                                       np.concatenate([u, v, psi]), h=1e-9))
    slow = modes[np.argmin(np.abs(modes))]
    fast = modes[np.argmax(np.abs(modes.imag))]
    assert slow.real == pytest.approx(-nu / (1 - b), rel=1e-3) and abs(slow.imag) < 1e-9
    assert fast.real == pytest.approx(nu * b / (2 * (1 - b)), rel=1e-2)
    assert abs(fast.imag) == pytest.approx(np.sqrt(1 - b), rel=1e-3)
    a = 0.1
    K, u, v, psi = _steady_single_block(a, b, nu)
    modes = np.linalg.eigvals(jacobian(inertial_rhs(K, [0], a, b, nu, np.zeros(0)), 0.0,
                                       np.concatenate([u, v, psi]), h=1e-9))
    assert np.max(modes.real) < 0
    # from away from steady state (theta nu = e^0.5, at rest): settles to the plate rate
    t_end = 30 / nu
    _, _, vc, pc, _ = inertial(K, [0], a, b, nu, u, 0 * v, psi + 0.5, t_end, np.array([0.0, t_end]))
    assert vc[-1, 0] / nu == pytest.approx(1, abs=1e-3)
    assert np.exp(pc[-1, 0]) * nu == pytest.approx(1, abs=1e-3)
