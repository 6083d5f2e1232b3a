"""Full-chain baselines for single events, the codes a first implementation would be.

Both integrate every block of the chain, c-free frame, slips y since the onset, velocities v
and psi = ln theta, from the onset state (force f, psi p, epicenter sliding from rest):

    y' = v,  v' = f + nu t - y + l^2 (lap y) - a ln(1 + max(v, 0)) - b psi   (sliding blocks)
    y' = v' = 0                                                               (resting blocks)
    psi' = exp(-psi) - max(v, 0)                                              (every block)

A resting block starts when its force exceeds the static threshold,
f + nu t - y + l^2 (lap y) - b psi > 0; a sliding block sticks when v reaches 0.
Each returns (slip profile, wall seconds, block right-hand-side evaluations) or raises Timeout.
"""
import numpy as np

from .common import Clock


class Timeout(RuntimeError):
    """A baseline run exceeded its wall-time cap."""


def _laplacian(y):
    """Free-end discrete Laplacian of the slips."""
    out = np.empty_like(y)
    out[1:-1] = y[2:] - 2 * y[1:-1] + y[:-2]
    out[0] = y[1] - y[0]
    out[-1] = y[-2] - y[-1]
    return out


def numpy_rk4_event(f, p, epicenter, model, dt, max_seconds=float("inf")):
    """Fixed-step RK4 on all blocks; sticks and starts are applied only at the end of a step.

    Limits: a block that stops inside a step slides backwards until the step ends, and a start
    is late by up to dt, so the slip error is first order in dt for events with many sticks.
    """
    n = len(f)
    l2, nu, a, b = model.l ** 2, model.nu, model.a, model.b

    def rates(t, y, v, psi, moving):
        vp = np.maximum(v, 0.0)
        acc = f + nu * t - y + l2 * _laplacian(y) - a * np.log1p(vp) - b * psi
        return np.where(moving, v, 0.0), np.where(moving, acc, 0.0), np.exp(-psi) - vp

    y, v, psi = np.zeros(n), np.zeros(n), p.copy()
    moving = np.zeros(n, dtype=bool)
    moving[epicenter] = True
    t, steps = 0.0, 0
    clock = Clock(max_seconds)
    while moving.any():
        if clock.expired:
            raise Timeout(f"numpy-rk4 dt={dt:g}: over {max_seconds:g} s at t = {t:.3g}")
        k1 = rates(t, y, v, psi, moving)
        k2 = rates(t + dt / 2, y + dt / 2 * k1[0], v + dt / 2 * k1[1], psi + dt / 2 * k1[2], moving)
        k3 = rates(t + dt / 2, y + dt / 2 * k2[0], v + dt / 2 * k2[1], psi + dt / 2 * k2[2], moving)
        k4 = rates(t + dt, y + dt * k3[0], v + dt * k3[1], psi + dt * k3[2], moving)
        y = y + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        psi = psi + dt / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        t += dt
        steps += 1
        stuck = moving & (v <= 0)
        v[stuck] = 0.0
        moving &= ~stuck
        excess = f + nu * t - y + l2 * _laplacian(y) - b * psi
        moving |= (~moving) & (excess > 0)
    return y, clock.elapsed, 4 * steps * n


def scipy_event(f, p, epicenter, model, method="LSODA", rtol=1e-6, atol=1e-10, span=1.0,
                max_seconds=float("inf")):
    """scipy.integrate.solve_ivp on all 3N unknowns, sticks and starts located as ODE events.

    The state is interleaved (y_i, v_i, psi_i), so the Jacobian is banded (4 below, 2 above
    the diagonal): LSODA gets the band, Radau and BDF the sparsity pattern, and all of them form
    it by finite differences. Two terminal event functions locate the transitions: the smallest
    velocity of the sliding blocks crossing zero downwards (a stick) and the largest excess force
    of the resting blocks crossing zero upwards (a start); at each the block is switched and the
    solver restarts there, as the kernel does. Each restart costs a new start-up (first step
    size, Jacobian), so events with many sticks are slow. The solver runs in pieces of at most
    `span` time units. Work counts every call of the right-hand side (finite-difference
    Jacobians included) as N block evaluations; event-function calls are not counted.
    Limits: steps are error-controlled (rtol, atol on every unknown, psi of resting blocks
    included) but the error is not otherwise bounded; two transitions closer together than the
    root tolerance are taken one after the other.
    """
    from scipy.integrate import solve_ivp
    from scipy.sparse import coo_matrix

    n = len(f)
    l2, nu, a, b = model.l ** 2, model.nu, model.a, model.b
    moving = np.zeros(n, dtype=bool)
    moving[epicenter] = True
    calls = 0
    clock = Clock(max_seconds)

    def excess(t, y, psi):
        return f + nu * t - y + l2 * _laplacian(y) - b * psi

    def rhs(t, z):
        nonlocal calls
        calls += 1
        if clock.expired:
            raise Timeout(f"scipy {method} rtol={rtol:g}: over {max_seconds:g} s at t = {t:.3g}")
        y, v, psi = z[0::3], z[1::3], z[2::3]
        vp = np.maximum(v, 0.0)
        out = np.empty_like(z)
        out[0::3] = np.where(moving, v, 0.0)
        out[1::3] = np.where(moving, excess(t, y, psi) - a * np.log1p(vp), 0.0)
        out[2::3] = np.exp(-psi) - vp
        return out

    def sticks(t, z):
        return np.min(z[1::3][moving])

    def starts(t, z):
        return np.max(excess(t, z[0::3], z[2::3])[~moving]) if not moving.all() else -1.0

    sticks.terminal, sticks.direction = True, -1
    starts.terminal, starts.direction = True, 1
    if method == "LSODA":
        options = {"lband": 4, "uband": 2}
    else:
        i = np.arange(3 * n)
        offsets = np.arange(-4, 3)
        rows = np.repeat(i, len(offsets))
        cols = rows + np.tile(offsets, 3 * n)
        keep = (cols >= 0) & (cols < 3 * n)
        options = {"jac_sparsity": coo_matrix((np.ones(keep.sum()), (rows[keep], cols[keep])),
                                              shape=(3 * n, 3 * n)).tocsc()}
    z = np.zeros(3 * n)
    z[2::3] = p
    t = 0.0
    while moving.any():
        sol = solve_ivp(rhs, (t, t + span), z, method=method, rtol=rtol, atol=atol,
                        events=[sticks, starts], **options)
        if sol.status < 0:
            raise RuntimeError(f"scipy {method}: {sol.message}")
        t, z = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1 and len(sol.t_events[0]):        # a stick
            k = np.flatnonzero(moving)[np.argmin(z[1::3][moving])]
            z[3 * k + 1] = 0.0
            moving[k] = False
        elif sol.status == 1:                                # a start
            rest = np.flatnonzero(~moving)
            moving[rest[np.argmax(excess(t, z[0::3], z[2::3])[rest])]] = True
    return z[0::3].copy(), clock.elapsed, calls * n


BASELINES = {"numpy-rk4": numpy_rk4_event, "scipy": scipy_event}


def run_baseline(setting, f, p, epicenter, model, max_seconds):
    """Run a baseline Setting; returns (profile, seconds, block RHS evaluations)."""
    return BASELINES[setting.name](f, p, epicenter, model, max_seconds=max_seconds, **setting.kwargs)

