"""An independent, deliberately plain implementation of one event for cross-checks.

Full chain, physical variables (u, v, psi) with c kept, classical RK4 on every
block, sticking by clamping v at the end of a step (second order), onset by
checking every block after every step. Slow but simple; shares no code with
ensemble.model.
"""
import numba as nb
import numpy as np


def displacements_for(force, t, model):
    """u with (nu t - u) + l^2 lap u - c = force (free ends)."""
    n = len(force)
    A = np.eye(n) * (1.0 + 2 * model.l ** 2)
    A[0, 0] = A[-1, -1] = 1.0 + model.l ** 2
    idx = np.arange(n - 1)
    A[idx, idx + 1] = A[idx + 1, idx] = -model.l ** 2
    return np.linalg.solve(A, model.nu * t - model.c - np.asarray(force))


@nb.njit
def _rates(t, u, v, psi, moving, nu, l2, a, b, c, du, dv, dpsi):
    n = u.shape[0]
    for i in range(n):
        left = u[i - 1] if i > 0 else u[i]
        right = u[i + 1] if i < n - 1 else u[i]
        if moving[i]:
            vp = max(v[i], 0.0)
            du[i] = v[i]
            dv[i] = (nu * t - u[i]) + l2 * (left - 2 * u[i] + right) - (c + a * np.log1p(vp) + b * psi[i])
            dpsi[i] = np.exp(-psi[i]) - vp
        else:
            du[i] = 0.0
            dv[i] = 0.0
            dpsi[i] = np.exp(-psi[i])


@nb.njit
def _event(t, u, v, psi, moving, nu, l2, a, b, c, dt, max_steps):
    n = u.shape[0]
    k = [np.zeros((3, n)) for _ in range(4)]
    t0 = t
    for _ in range(max_steps):
        if not moving.any():
            break
        base = (u.copy(), v.copy(), psi.copy())
        for s, (frac, w) in enumerate(((0.0, 1.0), (0.5, 2.0), (0.5, 2.0), (1.0, 1.0))):
            if s == 0:
                su, sv, sp = base
            else:
                su = base[0] + frac * dt * k[s - 1][0]
                sv = base[1] + frac * dt * k[s - 1][1]
                sp = base[2] + frac * dt * k[s - 1][2]
            _rates(t + frac * dt, su, sv, sp, moving, nu, l2, a, b, c, k[s][0], k[s][1], k[s][2])
        u[:] = base[0] + dt / 6 * (k[0][0] + 2 * k[1][0] + 2 * k[2][0] + k[3][0])
        v[:] = base[1] + dt / 6 * (k[0][1] + 2 * k[1][1] + 2 * k[2][1] + k[3][1])
        psi[:] = base[2] + dt / 6 * (k[0][2] + 2 * k[1][2] + 2 * k[2][2] + k[3][2])
        t += dt
        for i in range(n):
            if moving[i] and v[i] <= 0.0:
                moving[i] = False
                v[i] = 0.0
        for i in range(n):
            if not moving[i]:
                left = u[i - 1] if i > 0 else u[i]
                right = u[i + 1] if i < n - 1 else u[i]
                force = (nu * t - u[i]) + l2 * (left - 2 * u[i] + right)
                if force > c + b * psi[i]:
                    moving[i] = True
    return t - t0


def reference_event(force, psi, epicenter, model, dt, v_start=0.0, t_start=1.0e3):
    """Slip profile and duration of the event starting at `epicenter` (c-free force input)."""
    u = displacements_for(force, t_start, model)
    u0 = u.copy()
    v = np.zeros(len(u))
    v[epicenter] = v_start
    moving = np.zeros(len(u), dtype=np.bool_)
    moving[epicenter] = True
    duration = _event(t_start, u, v, np.array(psi, dtype=float), moving, model.nu, model.l ** 2,
                      model.a, model.b, model.c, dt, 10**8)
    return {"profile": u - u0, "duration": duration}
