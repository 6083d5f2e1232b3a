"""Steps of the event integrators on the active set (pure numba kernels).

Every stepper advances the sliding blocks from the step-start values (columns
Y0, V0, P0 of W) by h into (Y, V, P), leaves the derivative at the step start in
K1V (for the Hermite interpolant), and returns (friction work, time integral of
the total slip, error estimate relative to the tolerances; 0 for fixed steps).

- rk4_step: classical RK4, the paper's method; stable only while h / theta < 2.785.
- ark3_step: the additive (IMEX) Runge-Kutta pair ARK3(2)4L[2]SA of Kennedy &
  Carpenter (2003): explicit for slip and velocity, L-stable ESDIRK for the state
  psi, whose relaxation at rate 1/theta (~ v while sliding) is the stiff part.
  Each implicit stage is one scalar equation per block, solved by Newton. Third
  order with a second-order embedded estimate for step-size control.
"""
import math

import numba as nb

from .friction import friction, left, right, spring_force, state_rate
from .workspace import (ARK_A, ARK_G, ARK_V, F0, K1V, KP, KV, KY, P, P0, PS, SP, SV, SY, V, V0,
                        VS, Y, Y0, YS)


@nb.njit(cache=True, error_model="numpy")
def stage_rates(W, act, na, n, tau, l2, nu, a, b, yrest):
    """Derivatives of all active blocks at stage state (YS, VS, PS) into KY, KV, KP.

    Returns the friction power sum(Phi v) and the total slip sum(y) at the stage
    (for the energy balance).
    """
    power = 0.0
    ysum = yrest
    for k in range(na):
        i = act[k]
        v = W[i, VS]
        psi = W[i, PS]
        phi = friction(v, psi, a, b)
        W[i, KY] = v
        W[i, KV] = spring_force(W[i, F0], tau, nu, l2, W[left(i), YS], W[i, YS],
                                W[right(i, n), YS]) - phi
        W[i, KP] = state_rate(v, psi)
        if v > 0.0:
            power += phi * v
        ysum += W[i, YS]
    return power, ysum


@nb.njit(cache=True, error_model="numpy")
def rk4_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol):
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
                W[i, PS] = W[i, P0] + frac * h * W[i, KP]
        else:
            for k in range(na):
                i = act[k]
                W[i, YS] = W[i, Y0]
                W[i, VS] = W[i, V0]
                W[i, PS] = W[i, P0]
        power, ysum = stage_rates(W, act, na, n, tau + frac * h, l2, nu, a, b, yrest)
        pw += weight * power
        ys += weight * ysum
        for k in range(na):
            i = act[k]
            if stage == 0:
                W[i, K1V] = W[i, KV]
                W[i, SY] = W[i, KY]
                W[i, SV] = W[i, KV]
                W[i, SP] = W[i, KP]
            else:
                W[i, SY] += weight * W[i, KY]
                W[i, SV] += weight * W[i, KV]
                W[i, SP] += weight * W[i, KP]
    for k in range(na):
        i = act[k]
        W[i, Y] = W[i, Y0] + h / 6.0 * W[i, SY]
        W[i, V] = W[i, V0] + h / 6.0 * W[i, SV]
        W[i, P] = W[i, P0] + h / 6.0 * W[i, SP]
        W[i, YS] = W[i, Y]
    return pw * h / 6.0, ys * h / 6.0, 0.0




# ARK3(2)4L[2]SA (Kennedy & Carpenter 2003): c, explicit and implicit tableaux
# (lower triangles), weights b (shared, stiffly accurate) and embedded weights.
_G = 1767732205903.0 / 4055673282236.0
_C = (0.0, 1767732205903.0 / 2027836641118.0, 0.6, 1.0)
_AE = ((0.0, 0.0, 0.0),
       (1767732205903.0 / 2027836641118.0, 0.0, 0.0),
       (5535828885825.0 / 10492691773637.0, 788022342437.0 / 10882634858940.0, 0.0),
       (6485989280629.0 / 16251701735622.0, -4246266847089.0 / 9704473918619.0,
        10755448449292.0 / 10357097424841.0))
_AI = ((0.0, 0.0, 0.0),
       (_G, 0.0, 0.0),
       (2746238789719.0 / 10658868560708.0, -640167445237.0 / 6845629431997.0, 0.0),
       (1471266399579.0 / 7840856788654.0, -4482444167858.0 / 7529755066697.0,
        11266239266428.0 / 11593286722821.0))
_B = (1471266399579.0 / 7840856788654.0, -4482444167858.0 / 7529755066697.0,
      11266239266428.0 / 11593286722821.0, _G)
_BHAT = (2756255671327.0 / 12835298489170.0, -10771552573575.0 / 22201958757719.0,
         9247589265047.0 / 10645013368117.0, 2193209047091.0 / 5459859503100.0)


@nb.njit(cache=True, inline="always")
def _implicit_state(rhs, hg, v, guess):
    """psi with psi - hg (exp(-psi) - max(v, 0)) = rhs, Newton from `guess`.

    The left side is increasing and concave in psi, so Newton's iterates reach
    the root from below after the first step and never overshoot it.
    """
    target = rhs - hg * (v if v > 0.0 else 0.0)
    psi = guess
    for _ in range(60):
        e = hg * math.exp(-psi)
        step = (psi - e - target) / (1.0 + e)
        psi -= step
        if abs(step) <= 1e-15 * (1.0 + abs(psi)):
            break
    return psi


@nb.njit(cache=True, error_model="numpy")
def ark3_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol):
    """ARK3(2)4L[2]SA step of the active blocks; see the module docstring."""
    pw = 0.0
    ys = 0.0
    for s in range(4):
        for k in range(na):
            i = act[k]
            y = W[i, Y0]
            v = W[i, V0]
            r = W[i, P0]
            for j in range(s):
                y += h * _AE[s][j] * W[i, ARK_V + j]
                v += h * _AE[s][j] * W[i, ARK_A + j]
                r += h * _AI[s][j] * W[i, ARK_G + j]
            W[i, YS] = y
            W[i, VS] = v
            # the previous stage's psi (still in PS) starts Newton close to the root
            W[i, PS] = r if s == 0 else _implicit_state(r, h * _G, v, W[i, PS])
        power, ysum = stage_rates(W, act, na, n, tau + _C[s] * h, l2, nu, a, b, yrest)
        pw += _B[s] * power
        ys += _B[s] * ysum
        for k in range(na):
            i = act[k]
            W[i, ARK_V + s] = W[i, KY]
            W[i, ARK_A + s] = W[i, KV]
            W[i, ARK_G + s] = W[i, KP]
    err = 0.0
    for k in range(na):
        i = act[k]
        W[i, K1V] = W[i, ARK_A]
        dy = dv = dp = 0.0
        ey = ev = ep = 0.0
        for s in range(4):
            dy += _B[s] * W[i, ARK_V + s]
            dv += _B[s] * W[i, ARK_A + s]
            dp += _B[s] * W[i, ARK_G + s]
            d = _B[s] - _BHAT[s]
            ey += d * W[i, ARK_V + s]
            ev += d * W[i, ARK_A + s]
            ep += d * W[i, ARK_G + s]
        W[i, Y] = W[i, Y0] + h * dy
        W[i, V] = W[i, V0] + h * dv
        W[i, P] = W[i, P0] + h * dp
        W[i, YS] = W[i, Y]
        e1 = abs(h * ey) / (atol + rtol * max(abs(W[i, Y0]), abs(W[i, Y])))
        e2 = abs(h * ev) / (atol + rtol * max(abs(W[i, V0]), abs(W[i, V])))
        e3 = abs(h * ep) / (atol + rtol * max(abs(W[i, P0]), abs(W[i, P]), 1.0))
        err = max(err, e1, e2, e3)
    return pw * h, ys * h, err
