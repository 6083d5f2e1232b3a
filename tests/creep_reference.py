"""An independent reference for quasi-static creep (docs/numerics.md, "Quasi-static creep"): the full
inertial equations of a few blocks solved by scipy's stiff integrator, beside the quasi-static velocities
the creep phase is derived to give. Plain numpy and scipy, no package code: it checks the derivation.

Blocks i = 0..n-1 of a chain with free ends, c-free frame (friction a ln(1 + v) + b psi, psi = ln theta,
aging law psi' = exp(-psi) - v). A block listed in `creeping` slides; every other block is held at rest
(v = 0): the reference is for a cluster whose neighbours stay stuck, which the caller checks (their
force stays below b psi).
"""
import numpy as np
from scipy.integrate import solve_ivp


def stiffness(n, l):
    """K = I - l^2 L: the loader spring and the inter-block springs of a free-ended chain of n blocks
    (force on block i is nu t - (K u)_i)."""
    K = np.diag(np.full(n, 1.0 + 2 * l * l))
    K[0, 0] = K[-1, -1] = 1.0 + l * l
    if n == 1:
        K[0, 0] = 1.0
    for i in range(n - 1):
        K[i, i + 1] = K[i + 1, i] = -l * l
    return K


def cluster_matrix(K, creeping, b):
    """M = K_C - b I of the creeping cluster C (its rows and columns of K): the quasi-static creep of
    the aging law with a = 0 exists, unique and attracting, while M is positive definite."""
    C = np.asarray(creeping)
    return K[np.ix_(C, C)] - b * np.eye(len(C))


def quasi_static_velocity(K, creeping, b, nu, psi):
    """The creeping blocks' velocities on the quasi-static manifold (aging law, a = 0):
    (K_C - b I) v_C = nu - b exp(-psi_C)."""
    C = np.asarray(creeping)
    return np.linalg.solve(cluster_matrix(K, C, b), nu - b * np.exp(-psi[C]))


def on_the_manifold(K, creeping, b, nu, psi_c, u_rest):
    """A state on the quasi-static manifold at t = 0: the cluster's positions such that every creeping
    block's force equals its friction b psi, its velocities from quasi_static_velocity; the blocks at
    rest at u_rest. Returns (u, v, psi) of all blocks (psi of the resting blocks: psi_c's mean)."""
    n = K.shape[0]
    C = np.asarray(creeping)
    R = np.setdiff1d(np.arange(n), C)
    psi = np.full(n, np.mean(psi_c))
    psi[C] = psi_c
    u = np.zeros(n)
    u[R] = u_rest
    # force_C = -(K u)_C = b psi_C  ->  K_CC u_C = -b psi_C - K_CR u_R
    u[C] = np.linalg.solve(K[np.ix_(C, C)], -b * psi[C] - K[np.ix_(C, R)] @ u[R])
    v = np.zeros(n)
    v[C] = quasi_static_velocity(K, C, b, nu, psi)
    return u, v, psi


def inertial_rhs(K, creeping, a, b, nu, u_rest):
    """f(t, y) of the full equations for the creeping blocks, y = (u_C, v_C, psi_C); the resting blocks at u_rest."""
    C = np.asarray(creeping)
    R = np.setdiff1d(np.arange(K.shape[0]), C)
    m = len(C)

    def rhs(t, y):
        u, v, psi = y[:m], y[m:2 * m], y[2 * m:]
        force = nu * t - K[np.ix_(C, C)] @ u - K[np.ix_(C, R)] @ u_rest
        friction = a * np.log1p(np.maximum(v, 0.0)) + b * psi
        return np.concatenate([v, force - friction, np.exp(-psi) - v])
    return rhs


def jacobian(rhs, t, y, h=1e-7):
    """Central differences of rhs at (t, y), column by column."""
    J = np.empty((len(y), len(y)))
    for k in range(len(y)):
        step = h * max(1.0, abs(y[k]))
        up, down = y.copy(), y.copy()
        up[k] += step
        down[k] -= step
        J[:, k] = (rhs(t, up) - rhs(t, down)) / (2 * step)
    return J


def inertial(K, creeping, a, b, nu, u0, v0, psi0, t_end, t_eval, rtol=1e-10, atol=1e-14):
    """The full equations u'' = nu t - K u - a ln(1 + v) - b psi, psi' = exp(-psi) - v for the creeping
    blocks (the others held at rest), by Radau; returns (t, u, v, psi) at t_eval (arrays over the
    creeping blocks, rows = times) and the force on each resting block (rows = times)."""
    C = np.asarray(creeping)
    R = np.setdiff1d(np.arange(K.shape[0]), C)
    m = len(C)
    u_rest = u0[R]
    rhs = inertial_rhs(K, C, a, b, nu, u_rest)
    y0 = np.concatenate([u0[C], v0[C], psi0[C]])
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="Radau", t_eval=t_eval, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(sol.message)
    u, v, psi = sol.y[:m].T, sol.y[m:2 * m].T, sol.y[2 * m:].T
    rest_force = (nu * sol.t[:, None] - u @ K[np.ix_(R, C)].T - (K[np.ix_(R, R)] @ u_rest)[None, :])
    return sol.t, u, v, psi, rest_force
