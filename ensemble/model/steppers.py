"""Steps of the event integrators on the active set (pure numba kernels).

Every stepper advances the sliding blocks from the step-start values (columns
Y0, V0, P0 of W) by h into (Y, V, P) with the parameters p (params.KernelParams),
leaves the derivative at the step start in K1V (for the Hermite interpolant), and
returns (friction work, time integral of the total slip, error estimate relative
to the tolerances; 0 for fixed steps).

The event loop calls them through methods.take_step, which also says where the step's first stage
is (`first`, one of FIRST_* below) and returns the sums of the friction power and of the total slip
at the step's first and last evaluation: a stepper whose last evaluation is at the new state
(exponential.exp_step) reuses it as the next step's first (FSAL), and a retry from the same start
reuses its first stage. The steppers here evaluate every stage (rk4_stepper and ark_stepper give them
take_step's arguments and returns).

- rk4_step: classical RK4, the paper's method; stable only while h / theta < 2.785.
- ark_step: a step of an additive (IMEX) Runge-Kutta pair of tableaux.py, such as ARK3(2)4L[2]SA,
  ARK4(3)6L[2]SA and ARK5(4)8L[2]SA of Kennedy & Carpenter (2003): explicit for slip and velocity,
  L-stable ESDIRK for the state psi, whose relaxation at rate 1/theta (~ v while
  sliding) is the stiff part. Each implicit stage is one scalar equation per
  block, solved by the law's implicit_state. Order p with an embedded estimate of order p - 1 for
  step-size control. Each method of the registry (methods.py) runs it with its own tableau.
"""
from typing import NamedTuple

import numba as nb
import numpy as np

from .geometry import spring_force
from .laws import friction, has_state, implicit_state, loader_moves, state_rate
from .workspace import (ARK_A, ARK_G, ARK_V, F0, K1V, KP, KV, KY, P, P0, PS, SP, SV, SY, V, V0,
                        VS, Y, Y0, YS)

# where the first stage of a step is (methods.take_step's argument `first`); each reuse is exact, so
# a stepper may always evaluate instead
FIRST_NEW = 0     # evaluate it
FIRST_LAST = 1    # the previous step's last evaluation, at the state it accepted, unchanged since
                  # (no block started or stopped, no cut): this step's start
FIRST_KEPT = 2    # the previous call's first stage: a retry (rejected, or cut at a transition) from
                  # the same start


@nb.njit(cache=True, error_model="numpy")
def stage_rates(W, act, na, n, tau, p, yrest, with_state=True):
    """Derivatives of all active blocks at stage state (YS, VS, PS) into KY, KV, KP (p: KernelParams).

    with_state=False leaves KP alone (an implicit stage already knows it).

    Returns the friction power sum(Phi v) and the total slip sum(y) at the stage
    (for the energy balance).
    """
    power = 0.0
    ysum = yrest
    nu = p.nu if loader_moves(p.law) else 0.0
    for k in range(na):
        i = act[k]
        v = W[i, VS]
        psi = W[i, PS]
        phi = friction(p.law, v, psi)
        W[i, KY] = v
        W[i, KV] = spring_force(p.geom, W, YS, i, n, W[i, F0], tau, nu) - phi
        if with_state and has_state(p.law):
            W[i, KP] = state_rate(p.law, v, psi)
        if v > 0.0:
            power += phi * v
        ysum += W[i, YS]
    return power, ysum


@nb.njit(cache=True, error_model="numpy", inline="always")
def stage_columns(W, act, na, n, tau, p, yrest, s, weight, with_state, keep_state, pw, ys):
    """Stage s of a Runge-Kutta step, at the stage state (YS, VS, PS) and time tau: its rates
    (stage_rates, with_state as there) kept in the stage's columns ARK_V + s, ARK_A + s, and the
    state's rate KP in ARK_G + s if keep_state. Returns the quadratures (pw, ys) of the friction
    power and the total slip with the stage's terms, times its weight, added."""
    power, ysum = stage_rates(W, act, na, n, tau, p, yrest, with_state)
    for k in range(na):
        i = act[k]
        W[i, ARK_V + s] = W[i, KY]
        W[i, ARK_A + s] = W[i, KV]
        if keep_state:
            W[i, ARK_G + s] = W[i, KP]
    return pw + weight * power, ys + weight * ysum


NO_SUMS = (0.0, 0.0)   # a stepper that evaluates every stage passes on no sums (methods.take_step)


class ClassicalRK4(NamedTuple):
    """Classical RK4 at the fixed step integrator.dt, as the registry sees a scheme (methods.Method):
    no embedded pair (embedded_order None: the step is not controlled), no error weights."""
    name: str = "classical RK4"
    c: tuple = (0.0, 0.5, 0.5, 1.0)
    embedded_order: object = None
    kind = "fixed step"

    def stepper(self):
        return rk4_stepper

    def error_weights(self):
        return np.zeros(0)

    def refusal(self, law):
        return None


@nb.njit(error_model="numpy")
def rk4_stepper(W, act, na, n, tau, h, p, yrest, first, at_first):
    """rk4_step with methods.take_step's arguments and returns."""
    work, slip_time, err = rk4_step(W, act, na, n, tau, h, p, yrest)
    return work, slip_time, err, NO_SUMS, NO_SUMS


def ark_stepper(c, ae, ai, bw, bd, gamma):
    """ark_step with the pair's arrays (tableaux.ArkPair.kernel_arrays) frozen in, with
    methods.take_step's arguments and returns: one compiled copy per pair."""
    def step(W, act, na, n, tau, h, p, yrest, first, at_first):
        work, slip_time, err = ark_step(W, act, na, n, tau, h, p, yrest, c, ae, ai, bw, bd, gamma)
        return work, slip_time, err, NO_SUMS, NO_SUMS
    return nb.njit(error_model="numpy")(step)


@nb.njit(cache=True, error_model="numpy")
def rk4_step(W, act, na, n, tau, h, p, yrest):
    """Classical RK4: advance the active blocks from the step-start values (Y0, V0, P0) by h.

    Resting blocks keep YS == Y, so neighbour slips are read from YS throughout.
    Returns the quadratures of the friction power and of the total slip, and 0
    (no error estimate: fixed step).
    """
    pw = 0.0
    ys = 0.0
    for stage in range(4):
        if stage == 0:
            frac, weight = 0.0, 1.0
        elif stage == 3:
            frac, weight = 1.0, 1.0
        else:
            frac, weight = 0.5, 2.0
        if stage > 0:
            for k in range(na):
                i = act[k]
                W[i, YS] = W[i, Y0] + frac * h * W[i, KY]
                W[i, VS] = W[i, V0] + frac * h * W[i, KV]
                if has_state(p.law):
                    W[i, PS] = W[i, P0] + frac * h * W[i, KP]
        else:
            for k in range(na):
                i = act[k]
                W[i, YS] = W[i, Y0]
                W[i, VS] = W[i, V0]
                W[i, PS] = W[i, P0]
        power, ysum = stage_rates(W, act, na, n, tau + frac * h, p, yrest)
        pw += weight * power
        ys += weight * ysum
        for k in range(na):
            i = act[k]
            if stage == 0:
                W[i, K1V] = W[i, KV]
                W[i, SY] = W[i, KY]
                W[i, SV] = W[i, KV]
                if has_state(p.law):
                    W[i, SP] = W[i, KP]
            else:
                W[i, SY] += weight * W[i, KY]
                W[i, SV] += weight * W[i, KV]
                if has_state(p.law):
                    W[i, SP] += weight * W[i, KP]
    for k in range(na):
        i = act[k]
        W[i, Y] = W[i, Y0] + h / 6.0 * W[i, SY]
        W[i, V] = W[i, V0] + h / 6.0 * W[i, SV]
        if has_state(p.law):
            W[i, P] = W[i, P0] + h / 6.0 * W[i, SP]
        W[i, YS] = W[i, Y]
    return pw * h / 6.0, ys * h / 6.0, 0.0


@nb.njit(cache=True, error_model="numpy", inline="always")
def ark_step(W, act, na, n, tau, h, p, yrest, c, ae, ai, bw, bd, gamma):
    """One step of the IMEX pair (c, ae, ai, gamma; weights bw, error weights bd = b - bhat), as
    tableaux.ArkPair.kernel_arrays gives them (ark_stepper compiles one copy per pair).

    Stage s: slip and velocity explicit from the earlier stages' rates, psi
    implicit (one scalar solve per block) with diagonal gamma.
    """
    pw = 0.0
    ys = 0.0
    hg = h * gamma
    for s in range(c.shape[0]):
        for k in range(na):
            i = act[k]
            y = W[i, Y0]
            v = W[i, V0]
            for j in range(s):
                y += h * ae[s, j] * W[i, ARK_V + j]
                v += h * ae[s, j] * W[i, ARK_A + j]
            W[i, YS] = y
            W[i, VS] = v
            if has_state(p.law):
                r = W[i, P0]
                for j in range(s):
                    r += h * ai[s, j] * W[i, ARK_G + j]
                W[i, PS] = r
        if s > 0 and has_state(p.law):
            # the stiff state: psi - hg * state_rate(v, psi) = r, one scalar equation per block
            implicit_state(p.law, W, act, na, hg)
        pw, ys = stage_columns(W, act, na, n, tau + c[s] * h, p, yrest, s, bw[s], s == 0, has_state(p.law), pw, ys)
    err = 0.0
    for k in range(na):
        i = act[k]
        W[i, K1V] = W[i, ARK_A]
        dy = dv = dp = 0.0
        ey = ev = ep = 0.0
        for s in range(c.shape[0]):
            dy += bw[s] * W[i, ARK_V + s]
            dv += bw[s] * W[i, ARK_A + s]
            ey += bd[s] * W[i, ARK_V + s]
            ev += bd[s] * W[i, ARK_A + s]
            if has_state(p.law):
                dp += bw[s] * W[i, ARK_G + s]
                ep += bd[s] * W[i, ARK_G + s]
        W[i, Y] = W[i, Y0] + h * dy
        W[i, V] = W[i, V0] + h * dv
        if has_state(p.law):
            W[i, P] = W[i, P0] + h * dp
        W[i, YS] = W[i, Y]
        e1, e2, e3 = _error_norms(W, i, h * ey, h * ev, h * ep, p.rtol, p.atol)
        err = max(err, e1, e2, e3)
    return pw * h, ys * h, err


@nb.njit(cache=True, inline="always")
def _error_norms(W, i, dy, dv, dp, rtol, atol):
    """Block i's error estimates (dy, dv, dp) relative to the tolerances: slip, velocity, psi.

    Slip and psi scales are at least 1: a block that just started must not
    be held to the relative accuracy of its own vanishing slip (velocity
    stays relative: a nucleating block's slow start decides the event).
    """
    return (abs(dy) / (atol + rtol * max(abs(W[i, Y0]), abs(W[i, Y]), 1.0)),
            abs(dv) / (atol + rtol * max(abs(W[i, V0]), abs(W[i, V]))),
            abs(dp) / (atol + rtol * max(abs(W[i, P0]), abs(W[i, P]), 1.0)))


@nb.njit(cache=True)
def block_error(W, i, h, rtol, atol, bd):
    """(slip, velocity, psi) error norms of block i in the adaptive step of size h just taken,
    from the stages still in W; bd, the method's error weights (methods.error_weights).

    For diagnostics (the step trace): the step itself only keeps the largest.
    """
    ey = ev = ep = 0.0
    for s in range(bd.shape[0]):
        ey += bd[s] * W[i, ARK_V + s]
        ev += bd[s] * W[i, ARK_A + s]
        ep += bd[s] * W[i, ARK_G + s]
    return _error_norms(W, i, h * ey, h * ev, h * ep, rtol, atol)
