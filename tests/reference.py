"""An independent, deliberately plain implementation of one event for cross-checks.

Full chain, physical variables (u, v, psi) with c kept, classical RK4 on every
block, sticking by clamping v at the end of a step (second order), onset by
checking every block after every step. Slow but simple; shares no code with
ensemble.model.

The blocks may also lie on a plane (`nx` along strike, rows of nx across it, springs l^2 along and
l_y^2 across, free edges): block i at x = i % nx, y = i // nx. A chain is one row (nx = n), whose
across-strike springs never stretch.
"""
import numba as nb
import numpy as np


def stiffness_matrix(n, l, nx=None, l_y=None):
    """K, dense: the loader's spring 1 on the diagonal and a spring l^2 (along) or l_y^2 (across) per pair of
    neighbours (free ends and edges)."""
    nx = n if nx is None else nx
    K = np.eye(n)
    for i in range(n):
        links = []
        if i % nx < nx - 1 and i + 1 < n:
            links.append((i + 1, l ** 2))
        if i + nx < n:
            links.append((i + nx, (l if l_y is None else l_y) ** 2))
        for j, k2 in links:
            K[i, j] = K[j, i] = -k2
            K[i, i] += k2
            K[j, j] += k2
    return K


def displacements_for(force, t, model, nx=None, l_y=None):
    """u with (nu t - u) + l^2 lap u - c = force (free ends)."""
    A = stiffness_matrix(len(force), model.l, nx, l_y)
    return np.linalg.solve(A, model.nu * t - model.c - np.asarray(force))


@nb.njit(cache=True)
def _springs(u, i, l2, l2y, nx):
    """l^2 (u_right - 2 u_i + u_left) + l_y^2 (u_up - 2 u_i + u_down), a missing neighbour the block itself."""
    n = u.shape[0]
    x = i % nx
    left = u[i - 1] if x > 0 else u[i]
    right = u[i + 1] if x < nx - 1 else u[i]
    down = u[i - nx] if i >= nx else u[i]
    up = u[i + nx] if i + nx < n else u[i]
    return l2 * (left - 2 * u[i] + right) + l2y * (down - 2 * u[i] + up)


@nb.njit(cache=True)
def _rates(t, u, v, psi, moving, nu, springs, a, b, c, du, dv, dpsi):
    n = u.shape[0]
    l2, l2y, nx = springs
    for i in range(n):
        if moving[i]:
            vp = max(v[i], 0.0)
            du[i] = v[i]
            dv[i] = (nu * t - u[i]) + _springs(u, i, l2, l2y, nx) - (c + a * np.log1p(vp) + b * psi[i])
            dpsi[i] = np.exp(-psi[i]) - vp
        else:
            du[i] = 0.0
            dv[i] = 0.0
            dpsi[i] = np.exp(-psi[i])


@nb.njit(cache=True)
def _event(t, u, v, psi, moving, nu, springs, a, b, c, dt, max_steps):
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
            _rates(t + frac * dt, su, sv, sp, moving, nu, springs, a, b, c, k[s][0], k[s][1], k[s][2])
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
                force = (nu * t - u[i]) + _springs(u, i, *springs)
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
    duration = _event(t_start, u, v, np.array(psi, dtype=float), moving, model.nu, (model.l ** 2, 0.0, len(u)),
                      model.a, model.b, model.c, dt, 10**8)
    return {"profile": u - u0, "duration": duration}


# ---------------------------------------------------------------------------------------------
# Whole sequences: loading periods and events in one plain integration of the full chain.
#
# The state is (u, v, psi = ln theta) of every block and a flag `moving`, at time t; c is kept.
# Every step is classical RK4 on the full chain (resting blocks: u' = v' = 0, theta' = 1). After
# a step, if anything changed its regime inside it (a sliding block's v reached 0, a resting
# block's driving force exceeded its static threshold c + b psi), the step is redone with its
# length bisected (from the same start, 60 halvings) to the first instant at which it did, and
# the regime changes that hold there are applied. So every stick and every onset, during an
# event or in a loading period, is located to round-off of the step; no interpolant, no
# analytic onset formula, no active set.
#
# Step length: at most `dt` while a block slides, and at most `alpha` times the fastest time scale of the
# state equation (theta of any block, 1 / v of any sliding one), so that RK4 on
# psi' = 1 / theta - v stays accurate while theta is small (just after a block stops) and the
# steps grow with theta in a loading period (there the driving force grows as nu t and
# the threshold as b ln(theta + t): their difference is convex in t, so a crossing cannot
# hide between two step ends whatever the step).
# ---------------------------------------------------------------------------------------------

_BISECTIONS = 60


@nb.njit(cache=True)
def _rk4_step(t, t_lo, h, u, v, psi, moving, nu, springs, a, b, c):
    """(u, v, psi) after one classical RK4 step of length h from time t + t_lo (new arrays)."""
    n = u.shape[0]
    ku = np.zeros((4, n))
    kv = np.zeros((4, n))
    kp = np.zeros((4, n))
    fracs = (0.0, 0.5, 0.5, 1.0)
    for s in range(4):
        if s == 0:
            su, sv, sp = u, v, psi
        else:
            f = fracs[s] * h
            su = u + f * ku[s - 1]
            sv = v + f * kv[s - 1]
            sp = psi + f * kp[s - 1]
        _rates(t + (t_lo + fracs[s] * h), su, sv, sp, moving, nu, springs, a, b, c, ku[s], kv[s], kp[s])
    w = h / 6.0
    return (u + w * (ku[0] + 2 * ku[1] + 2 * ku[2] + ku[3]),
            v + w * (kv[0] + 2 * kv[1] + 2 * kv[2] + kv[3]),
            psi + w * (kp[0] + 2 * kp[1] + 2 * kp[2] + kp[3]))


@nb.njit(cache=True)
def _driving_force(t, u, i, nu, springs):
    """(nu t - u_i) + the springs' force (_springs), free ends (missing neighbour = the block)."""
    return (nu * t - u[i]) + _springs(u, i, *springs)


@nb.njit(cache=True)
def _changes(t, u, v, psi, moving, nu, springs, b, c):
    """Number of blocks whose regime changes in this state: sliding with v <= 0, or resting
    with the driving force above the static threshold c + b psi."""
    count = 0
    for i in range(u.shape[0]):
        if moving[i]:
            if v[i] <= 0.0:
                count += 1
        elif _driving_force(t, u, i, nu, springs) > c + b * psi[i]:
            count += 1
    return count


@nb.njit(cache=True)
def _sequence(u, v, psi, t, n_events, nu, springs, a, b, c, dt, alpha, max_steps,
              onset, epicenter, duration, slip):
    """Integrate from the state (u, v, psi) at time t (every block at rest) through n_events events.

    Fills onset[k], epicenter[k], duration[k] and slip[k, :] (the slip of every block) of event k;
    returns the number of events completed (fewer if max_steps ran out).
    """
    n = u.shape[0]
    moving = np.zeros(n, dtype=np.bool_)
    u_onset = u.copy()
    t_onset, t_onset_lo = t, 0.0
    t_lo = 0.0     # time is the unevaluated sum t + t_lo: ~1e6 steps at t ~ 1e5 would drift
    k = 0
    steps = 0
    while k < n_events and steps < max_steps:
        steps += 1
        h = dt if moving.any() else np.inf
        for i in range(n):
            h = min(h, alpha * np.exp(psi[i]))
            if moving[i] and v[i] > 0.0:
                h = min(h, alpha / v[i])
        u1, v1, psi1 = _rk4_step(t, t_lo, h, u, v, psi, moving, nu, springs, a, b, c)
        if _changes(t + (t_lo + h), u1, v1, psi1, moving, nu, springs, b, c) > 0:
            lo, hi = 0.0, h
            for _ in range(_BISECTIONS):
                mid = 0.5 * (lo + hi)
                um, vm, psim = _rk4_step(t, t_lo, mid, u, v, psi, moving, nu, springs, a, b, c)
                if _changes(t + (t_lo + mid), um, vm, psim, moving, nu, springs, b, c) > 0:
                    hi = mid
                else:
                    lo = mid
            h = hi
            u1, v1, psi1 = _rk4_step(t, t_lo, h, u, v, psi, moving, nu, springs, a, b, c)
        was_sliding = moving.any()
        u, v, psi = u1, v1, psi1
        s = t + h     # two-sum: t + t_lo += h exactly
        t_lo += (t - (s - (s - t))) + (h - (s - t))
        t = s
        # regime changes at t: stops first, then onsets of blocks that were at rest
        resting = ~moving
        for i in range(n):
            if moving[i] and v[i] <= 0.0:
                moving[i] = False
                v[i] = 0.0     # blocks never move backward
        first = -1
        largest = 0.0
        for i in range(n):
            if resting[i]:
                excess = _driving_force(t + t_lo, u, i, nu, springs) - (c + b * psi[i])
                if excess > 0.0:
                    moving[i] = True
                    if excess > largest:
                        largest = excess
                        first = i
        if not was_sliding and first >= 0:
            t_onset, t_onset_lo = t, t_lo
            u_onset[:] = u
            epicenter[k] = first
        if was_sliding and not moving.any():
            onset[k] = t_onset + t_onset_lo
            duration[k] = (t - t_onset) + (t_lo - t_onset_lo)
            slip[k, :] = u - u_onset
            k += 1
    return k


def reference_sequence(u, theta, t, n_events, *, nu, l, a, b, c, dt=1e-3, alpha=0.02,
                       max_steps=10**8, nx=None, l_y=None):
    """The first n_events events from displacements u and states theta at time t, all at rest.

    Plain parameters only (the chain's N is len(u), both ends free; on a plane nx blocks along strike and
    l_y across, l_y = l if not given). Returns a dict of arrays:
    "t" onset times, "epicenter" the block that started each event (the one furthest above
    its threshold if several start at once), "duration", "profile" (events x N) the slip
    Delta u_i of every block, "slip" its sum.
    """
    u = np.array(u, dtype=float)
    psi = np.log(np.array(theta, dtype=float))
    onset = np.full(n_events, np.nan)
    epicenter = np.full(n_events, -1, dtype=np.int64)
    duration = np.full(n_events, np.nan)
    profile = np.full((n_events, len(u)), np.nan)
    springs = (l ** 2, (l if l_y is None else l_y) ** 2 if nx is not None else 0.0, len(u) if nx is None else nx)
    done = _sequence(u, np.zeros(len(u)), psi, float(t), n_events, nu, springs, a, b, c, dt, alpha,
                     max_steps, onset, epicenter, duration, profile)
    if done < n_events:
        raise RuntimeError(f"reference: only {done} of {n_events} events within {max_steps} steps")
    return {"t": onset, "epicenter": epicenter, "duration": duration, "profile": profile,
            "slip": profile.sum(axis=1)}
