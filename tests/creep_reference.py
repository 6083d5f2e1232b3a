"""An independent reference for quasi-static creep (docs/numerics.md, "Quasi-static creep"): the full
inertial equations of a few blocks solved by scipy, beside the quasi-static velocities the creep phase is
derived to give. Plain numpy and scipy, no package code: it checks the derivation.

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
    blocks (the others held at rest), by scipy's DOP853; returns (t, u, v, psi) at t_eval (arrays over the
    creeping blocks, rows = times) and the force on each resting block (rows = times).

    Explicit, of order 8: the equations are not stiff where they are used here (their fastest time scale
    is the inertial oscillation, of order 1; the state relaxes over 1 / nu; a decays the oscillation over
    2 / a), and Radau at the same rtol took 2.4 to 4.4 times the evaluations and 5 to 12 times the time. The
    two agree on every error the tests measure against them to 1e-4 of its size or better (measured at rtol
    1e-10: a creeping cluster's deviation from the quasi-static velocities 1.1403268e-3 by Radau,
    1.1403868e-3 by DOP853, 1.1403336e-3 by DOP853 at 1e-12)."""
    C = np.asarray(creeping)
    R = np.setdiff1d(np.arange(K.shape[0]), C)
    m = len(C)
    u_rest = u0[R]
    rhs = inertial_rhs(K, C, a, b, nu, u_rest)
    y0 = np.concatenate([u0[C], v0[C], psi0[C]])
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(sol.message)
    u, v, psi = sol.y[:m].T, sol.y[m:2 * m].T, sol.y[2 * m:].T
    rest_force = (nu * sol.t[:, None] - u @ K[np.ix_(R, C)].T - (K[np.ix_(R, R)] @ u_rest)[None, :])
    return sol.t, u, v, psi, rest_force


# ---------------------------------------------------------------------------------------------------------
# Ruina's slip law: the whole cycle (rest, creep, inertial events) of a free chain of n blocks from the full
# inertial equations, with an exact stick rule. Plain numpy and scipy, no package code.
#
#   sliding block i:  u_i' = v_i,  v_i' = nu t - (K u)_i - a ln(1 + v_i) - b psi_i,  psi_i' = -v_i (psi_i + ln v_i)
#   resting block i:  u_i, psi_i constant (the slip law does not heal at rest), v_i = 0
#
# A sliding block whose velocity falls to 0 sticks if its force is then at most b psi_i (its static threshold;
# else it would accelerate again at once); a resting block restarts when its force reaches b psi_i. Only
# forward slip: a block at rest whose force is below its threshold (also a negative force) holds. While every
# block rests, the loader's spring alone changes the forces and the next restart is found in closed form.
# v ln v -> 0 as v -> 0: the state's rate uses max(v, 0), and a restarting block starts at V_START (its
# acceleration is 0 there and grows with the loading, so the first instants of its slip are below any
# tolerance used here).
# ---------------------------------------------------------------------------------------------------------

V_START = 1e-200


def _slip_rate(v, psi):
    vp = np.maximum(v, 0.0)
    vlnv = np.where(vp > 0.0, vp * np.log(np.where(vp > 0.0, vp, 1.0)), 0.0)
    return -(vp * psi + vlnv)


def slip_law_chain(n, l, a, b, nu, t_end, u0=None, psi0=None, v_marks=(1e-2, 1.0), max_sticks=None,
                   rtol=1e-10, atol=1e-13, max_step=np.inf):
    """The slip law's full equations of n blocks (loader spring 1, inter-block l^2, free ends) from rest at
    t = 0 (u0, psi0; default 0) to t_end, or until `max_sticks` sticks. Returns a list of transitions
    (t, what, block, u, v, psi): what is 'restart' (a resting block starts to slide), 'stick', or
    ('mark', vm) when a block's velocity rises through vm (v_marks: where an inertial event is counted
    to begin)."""
    K = stiffness(n, l)
    u = np.zeros(n) if u0 is None else np.array(u0, float)
    psi = np.zeros(n) if psi0 is None else np.array(psi0, float)
    v = np.zeros(n)
    resting = np.ones(n, bool)
    t = 0.0
    log = []
    sticks = 0
    marks = list(v_marks)

    def force(t, u):
        return nu * t - K @ u

    while t < t_end and (max_sticks is None or sticks < max_sticks):
        if resting.all():
            # every block at rest: the forces grow at nu, the thresholds stay
            gap = b * psi - force(t, u)
            j = int(np.argmin(gap))
            t = t + max(gap[j], 0.0) / nu
            if t >= t_end:
                break
            resting[j] = False
            v[j] = V_START
            log.append((t, "restart", j, u.copy(), v.copy(), psi.copy()))
            continue
        slide = ~resting

        t0 = t      # each phase integrates in its own time s = t - t0 (steps of 1e-3 at t = 1e11)

        def rhs(s, y, slide=slide):
            uu, vv, pp = y[:n], y[n:2 * n], y[2 * n:]
            f = force(t0 + s, uu)
            dv = f - a * np.log1p(np.maximum(vv, 0.0)) - b * pp
            dp = _slip_rate(vv, pp)
            return np.concatenate([np.where(slide, vv, 0.0), np.where(slide, dv, 0.0), np.where(slide, dp, 0.0)])

        def jac(t, y, slide=slide):
            vv, pp = y[n:2 * n], y[2 * n:]
            J = np.zeros((3 * n, 3 * n))
            s = np.flatnonzero(slide)
            vp = np.maximum(vv, 1e-300)
            for i in s:
                J[i, n + i] = 1.0
                J[n + i, :n] = -K[i]
                J[n + i, n + i] = -a / (1.0 + max(vv[i], 0.0))
                J[n + i, 2 * n + i] = -b
                J[2 * n + i, n + i] = -(pp[i] + np.log(vp[i]) + 1.0)
                J[2 * n + i, 2 * n + i] = -max(vv[i], 0.0)
            return J

        events = []
        for i in range(n):
            if slide[i]:
                def stop(t, y, i=i):
                    return y[n + i]
                stop.terminal, stop.direction = True, -1
                events.append(("stick", i, stop))
                for vm in marks:
                    def mark(t, y, i=i, vm=vm):
                        return y[n + i] - vm
                    mark.terminal, mark.direction = False, 1
                    events.append((("mark", vm), i, mark))
            else:
                def start(s, y, i=i):
                    return force(t0 + s, y[:n])[i] - b * y[2 * n + i]
                start.terminal, start.direction = True, 1
                events.append(("restart", i, start))
        y0 = np.concatenate([u, v, psi])
        sol = solve_ivp(rhs, (0.0, t_end - t0), y0, method="Radau", jac=jac, events=[e[2] for e in events],
                        rtol=rtol, atol=atol, max_step=max_step, dense_output=False)
        if sol.status < 0:
            raise RuntimeError(sol.message)
        # non-terminal marks in time order, then the terminal event (if any)
        hits = []
        for (what, i, _), te, ye in zip(events, sol.t_events, sol.y_events):
            for tk, yk in zip(te, ye):
                hits.append((t0 + tk, what, i, yk))
        hits.sort(key=lambda h: h[0])
        y = sol.y[:, -1]
        t = t0 + sol.t[-1]
        u, v, psi = y[:n].copy(), y[n:2 * n].copy(), y[2 * n:].copy()
        for tk, what, i, yk in hits:
            if isinstance(what, tuple):
                if tk <= t:
                    log.append((tk, what, i, yk[:n].copy(), yk[n:2 * n].copy(), yk[2 * n:].copy()))
        if sol.status == 1:
            what, i = None, None
            for tk, w, j, yk in hits:
                if not isinstance(w, tuple) and tk == t:
                    what, i = w, j
            if what == "stick":
                v[i] = 0.0
                if force(t, u)[i] - b * psi[i] <= 0.0:
                    resting[i] = True
                    sticks += 1
                    log.append((t, "stick", i, u.copy(), v.copy(), psi.copy()))
                else:
                    v[i] = V_START      # pressed on: slides on
            elif what == "restart":
                resting[i] = False
                v[i] = V_START
                log.append((t, "restart", i, u.copy(), v.copy(), psi.copy()))
    return log


def single_block_cycles(log, mark=1.0):
    """A single block's cycles from slip_law_chain's log: per cycle (t_restart, creep duration (restart to
    the velocity mark), creep slip, event slip (mark to stick), t_mark, t_stick, psi at restart)."""
    rows = []
    restart = mark_row = None
    for t, what, i, u, v, psi in log:
        if what == "restart":
            restart, mark_row = (t, u[0], psi[0]), None
        elif what == ("mark", mark) and restart is not None and mark_row is None:
            mark_row = (t, u[0])
        elif what == "stick" and restart is not None and mark_row is not None:
            rows.append((restart[0], mark_row[0] - restart[0], mark_row[1] - restart[1], u[0] - mark_row[1],
                         mark_row[0], t, restart[2]))
            restart = mark_row = None
    return np.array(rows)


def inertial_events(log, n, mark=1e-2):
    """The inertial events of slip_law_chain's log: an event begins when a block's velocity rises through
    `mark` while none is in an event, and ends when every block rests again. Rows (t_start, total slip of
    the event (all blocks), total slip of all blocks since the previous event's start, t_end, psi at the end)."""
    rows = []
    resting = np.ones(n, bool)
    start = None
    u_prev = None
    for t, what, i, u, v, psi in log:
        if what == "restart":
            resting[i] = False
        elif what == "stick":
            resting[i] = True
            if start is not None and resting.all():
                rows.append((start[0], u.sum() - start[1], start[1] - (u_prev if u_prev is not None else 0.0),
                             t, psi.copy()))
                u_prev = start[1]
                start = None
        elif what == ("mark", mark) and start is None:
            start = (t, u.sum())
    return rows
