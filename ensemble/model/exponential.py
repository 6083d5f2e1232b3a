"""The exponential integrator exp4: Krogstad's ETDRK4 in the state, classical RK4 in slip and velocity.

The aging law's state equation is linear in theta = exp(psi): theta' = s(v) - r(v) theta (s = 1,
r = v; laws: linear_state). Over a step from (y0, v0, theta0) the stiff part -r(v0) theta is solved
exactly (integrating factor) and only the remainder

    g(v, theta) = s(v) - (r(v) - r(v0)) theta        (smooth: ~ v0 / v in steady sliding)

is approximated, by Krogstad's exponential Runge-Kutta method (Krogstad 2005; Hochbruck & Ostermann,
Acta Numerica 19, 209, 2010, sec. 2.3), whose coefficients are the functions phi_k of z = h r(v0).
At z = 0 they are classical RK4's, which is what slip and velocity (linear part 0) see. A fifth
evaluation at the new state gives an embedded solution of order 3 (bhat = (1/6, 1/3, 1/3, 0, 1/6)
at z = 0; in the state b4(z) moves from stage 4 to stage 5), so the step is controlled like the ARK
methods'. The fifth evaluation is also the next step's first when no block started or stopped
(FSAL: 4 right-hand sides per step, exactly the numbers a fresh evaluation gives). Every stage is
explicit: one log per block (psi = ln theta for the friction), one expm1 per block and step.
Derivation and order conditions: docs/state_integrator.md.

A law without a state takes the classical part alone (adaptive RK4 with the embedded pair); a law
with a state not of this form is refused (methods.Method.refusal).
"""
import math
from typing import NamedTuple

import numba as nb
import numpy as np

from .laws import has_state, linear_state
from .steppers import FIRST_KEPT, FIRST_LAST, FIRST_NEW, _error_norms, stage_rates
from .workspace import (ARK_A, ARK_G, ARK_V, K1V, KV, KY, P, P0, PS, V, V0, VS, X_EH, X_P1, X_P1H, X_P2, X_P2H, X_P3,
                        X_RATE0, X_THETA, X_THETA0, Y, Y0, YS)


class ExponentialScheme(NamedTuple):
    """An exponential Runge-Kutta pair whose stepper is written out in this module (its
    coefficients are functions of z, not numbers): what the registry needs to know of it."""
    name: str
    order: int
    embedded_order: int
    c: tuple                 # nodes (the fifth is the new state)
    b_minus_bhat: tuple      # at z = 0 (the slip's and velocity's; methods.error_weights)
    kind = "adaptive exponential"

    def stepper(self):
        """exp_step, written out below for this scheme."""
        return exp_step

    def error_weights(self):
        return np.array(self.b_minus_bhat)

    def refusal(self, law):
        """Why the scheme cannot integrate `law` (laws.Law), or None: the state must be linear in theta."""
        if law.has_state and law.linear_state is None:
            return (f"needs a state equation linear in theta = exp(psi) (Law.linear_state), which "
                    f"model.law = {law.name!r} does not have")
        return None


ETDRK4_KROGSTAD = ExponentialScheme("ETDRK4 (Krogstad) with an embedded order 3", 4, 3,
                                    c=(0.0, 0.5, 0.5, 1.0, 1.0),
                                    b_minus_bhat=(0.0, 0.0, 0.0, 1.0 / 6.0, -1.0 / 6.0))

# classical RK4 rows (the exponential tableau at z = 0), and its weights
_A = ((0.0, 0.0, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0),
      (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0))
_B = (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0, 0.0)
_C = ETDRK4_KROGSTAD.c
_INV_FACTORIAL = np.array([1.0 / math.factorial(k) for k in range(20)])  # 1 / k!


@nb.njit(cache=True, inline="always")
def phis(x, em1):
    """(phi_1, phi_2, phi_3) at x <= 0, em1 = expm1(x); phi_k(x) = sum_m x^m / (m + k)!.

    Below |x| = 1/2 the series (16 terms: relative error < 1e-20), above it the recurrence
    phi_{k+1} = (phi_k - 1/k!) / x, which loses at most ~6 eps there.
    """
    if x > -0.5:
        p1 = p2 = p3 = 0.0
        for m in range(15, -1, -1):   # Horner from the top term
            p1 = p1 * x + _INV_FACTORIAL[m + 1]
            p2 = p2 * x + _INV_FACTORIAL[m + 2]
            p3 = p3 * x + _INV_FACTORIAL[m + 3]
        return p1, p2, p3
    p1 = em1 / x
    p2 = (p1 - 1.0) / x
    p3 = (p2 - 0.5) / x
    return p1, p2, p3


# fastmath on this function's own arithmetic (and what is inlined into it; stage_rates and the laws keep
# theirs): contract (fused multiply-adds in the phi series and the stage sums), arcp (reciprocals for four
# divisions), afn, nsz; never nnan or ninf: a NaN or inf error norm must reject the step (below). Changes
# exp4's last bits; measured in docs/benchmarks.md (exp4).
_FASTMATH = {"contract", "afn", "arcp", "nsz"}


@nb.njit(cache=True, error_model="numpy", fastmath=_FASTMATH)
def exp_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    """One exp4 step of the active blocks from (Y0, V0, P0) by h (steppers.py's contract).

    Stage s: slip and velocity from the classical rows; theta from Krogstad's rows in the stage
    remainders g (ARK_G), psi = ln theta. Stage 5 is the new state. Returns (friction work, time
    integral of the total slip, error norm, at_first, at_last: methods.take_step); the error of psi
    is that of theta relative to theta. On return ARK_G + 3 and + 4 hold the remainders scaled so
    that steppers.block_error, with the weights (0, 0, 0, 1/6, -1/6), gives the psi error of the
    step.

    Stage 5's rates are the next step's first stage's (first = FIRST_LAST: copied from its columns,
    the same numbers), and a retry keeps the first stage it had (FIRST_KEPT: its rates, theta0,
    r(v0) and g0 do not depend on h).
    """
    state = has_state(p.law)
    if state:
        for k in range(na):
            i = act[k]
            if first != FIRST_KEPT:
                W[i, X_THETA0] = math.exp(W[i, P0])
                W[i, X_RATE0] = _linear_state(p.law, W[i, V0])[1]
            r0 = W[i, X_RATE0]
            x = -0.5 * h * r0
            em1h = math.expm1(x)
            p1h, p2h, _ = phis(x, em1h)
            p1, p2, p3 = phis(2.0 * x, em1h * (2.0 + em1h))
            W[i, X_EH] = 1.0 + em1h
            W[i, X_P1H] = p1h
            W[i, X_P2H] = p2h
            W[i, X_P1] = p1
            W[i, X_P2] = p2
            W[i, X_P3] = p3
    pw = 0.0
    ys = 0.0
    at_last = at_first
    for s in range(5):
        if s > 0 or first != FIRST_KEPT:
            for k in range(na):
                i = act[k]
                y = W[i, Y0]
                v = W[i, V0]
                for j in range(s):
                    y += h * _A[s][j] * W[i, ARK_V + j]
                    v += h * _A[s][j] * W[i, ARK_A + j]
                W[i, YS] = y
                W[i, VS] = v
                if state:
                    if s == 0:
                        theta = W[i, X_THETA0]
                        W[i, PS] = W[i, P0]
                    else:
                        theta = _stage_theta(W, i, s, h)
                        W[i, PS] = math.log(theta)
                    W[i, X_THETA] = theta
                    # the stage's remainder: a function of its v and theta alone, not of its rates
                    sr = linear_state(p.law, v)
                    W[i, ARK_G + s] = sr[0] - (sr[1] - W[i, X_RATE0]) * theta
        if s > 0 or first == FIRST_NEW:
            at_stage = stage_rates(W, act, na, n, tau + _C[s] * h, p, yrest, False)
            for k in range(na):
                i = act[k]
                W[i, ARK_V + s] = W[i, KY]
                W[i, ARK_A + s] = W[i, KV]
        else:
            if first == FIRST_LAST:
                for k in range(na):
                    i = act[k]
                    W[i, ARK_V] = W[i, ARK_V + 4]
                    W[i, ARK_A] = W[i, ARK_A + 4]
            at_stage = at_first
        # (as steppers.stage_columns sums them)
        pw = pw + _B[s] * at_stage[0]
        ys = ys + _B[s] * at_stage[1]
        if s == 0:
            at_first = at_stage
        at_last = at_stage
    err = 0.0
    for k in range(na):
        i = act[k]
        W[i, K1V] = W[i, ARK_A]
        W[i, Y] = W[i, YS]
        W[i, V] = W[i, VS]
        ep = 0.0
        if state:
            W[i, P] = W[i, PS]
            # b4(z) (g4 - g5) h / theta: the state's error relative to theta, psi's error
            b4 = 4.0 * W[i, X_P3] - W[i, X_P2]
            scale = 6.0 * b4 / W[i, X_THETA]
            W[i, ARK_G + 3] *= scale
            W[i, ARK_G + 4] *= scale
            ep = h / 6.0 * (W[i, ARK_G + 3] - W[i, ARK_G + 4])
        ey = h / 6.0 * (W[i, ARK_V + 3] - W[i, ARK_V + 4])
        ev = h / 6.0 * (W[i, ARK_A + 3] - W[i, ARK_A + 4])
        e1, e2, e3 = _error_norms(W, i, ey, ev, ep, p.rtol, p.atol)
        e = e1 + e2 + e3
        # (max would drop a NaN): a stage's theta <= 0 (far too long a step in a fast change of v)
        # or a blow-up is an infinite error, and the step is retried shorter
        err = max(err, e1, e2, e3) if math.isfinite(e) else math.inf
    return pw * h, ys * h, err, at_first, at_last


@nb.njit(cache=True)
def _linear_state(law, v):
    """The law's linear_state (a call of its own, as creep._rate: numba's inliner, which inlines
    linear_state into a lambda, mislabels a variable when it is inlined twice in one function)."""
    return linear_state(law, v)


@nb.njit(cache=True, inline="always")
def _stage_theta(W, i, s, h):
    """theta of stage s >= 1 (Krogstad's rows; stage 4 is the new state, the weights b(z))."""
    eh = W[i, X_EH]
    g0 = W[i, ARK_G]
    if s == 1:
        return eh * W[i, X_THETA0] + h * 0.5 * W[i, X_P1H] * g0
    if s == 2:
        p2h = W[i, X_P2H]
        return eh * W[i, X_THETA0] + h * ((0.5 * W[i, X_P1H] - p2h) * g0 + p2h * W[i, ARK_G + 1])
    p1, p2 = W[i, X_P1], W[i, X_P2]
    if s == 3:
        return eh * eh * W[i, X_THETA0] + h * ((p1 - 2.0 * p2) * g0 + 2.0 * p2 * W[i, ARK_G + 2])
    p3 = W[i, X_P3]
    b23 = 2.0 * p2 - 4.0 * p3
    return eh * eh * W[i, X_THETA0] + h * ((p1 - 3.0 * p2 + 4.0 * p3) * g0
                                            + b23 * (W[i, ARK_G + 1] + W[i, ARK_G + 2])
                                            + (4.0 * p3 - p2) * W[i, ARK_G + 3])
