"""Steps of the event integrators on the active set (pure numba kernels).

Every stepper advances the sliding blocks from the step-start values (columns
Y0, V0, P0 of W) by h into (Y, V, P), leaves the derivative at the step start in
K1V (for the Hermite interpolant), and returns (friction work, time integral of
the total slip, error estimate relative to the tolerances; 0 for fixed steps).

- rk4_step: classical RK4, the paper's method; stable only while h / theta < 2.785.
- ark3_step, ark4_step, ark5_step: the additive (IMEX) Runge-Kutta pairs ARK3(2)4L[2]SA,
  ARK4(3)6L[2]SA and ARK5(4)8L[2]SA of Kennedy & Carpenter (2003): explicit for slip and velocity,
  L-stable ESDIRK for the state psi, whose relaxation at rate 1/theta (~ v while
  sliding) is the stiff part. Each implicit stage is one scalar equation per
  block, solved by Newton. Order p with an embedded estimate of order p - 1 for
  step-size control. All run the same kernel `_ark_step` with their tableau.
"""
import math
from fractions import Fraction
from typing import NamedTuple

import numba as nb
import numpy as np

from .friction import friction, left, right, spring_force, state_rate
from .workspace import (ARK_A, ARK_G, ARK_V, F0, K1V, KP, KV, KY, P, P0, PS, SP, SV, SY, V, V0,
                        VS, Y, Y0, YS)


@nb.njit(cache=True, error_model="numpy")
def stage_rates(W, act, na, n, tau, l2, nu, a, b, yrest, with_state=True):
    """Derivatives of all active blocks at stage state (YS, VS, PS) into KY, KV, KP.

    with_state=False leaves KP alone (an implicit stage already knows it).

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
        if with_state:
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


class ArkPair(NamedTuple):
    """An IMEX additive Runge-Kutta pair as published, in exact fractions ("p/q" strings).

    Explicit and ESDIRK tableaux share the nodes c and the weights b (the
    implicit one is stiffly accurate: its last row is b); bhat are the embedded
    weights. `explicit[s]` and `implicit[s]` are row s left of the diagonal;
    the implicit diagonal is gamma except for the explicit first stage.
    """
    name: str
    order: int
    embedded_order: int
    c: tuple
    explicit: tuple
    implicit: tuple
    gamma: str
    b: tuple
    bhat: tuple

    def matrices(self):
        """(c, A_E, A_I, b, bhat) as Fractions; A_E and A_I square, A_I with its diagonal."""
        g = Fraction(self.gamma)
        ai = _square(self.implicit)
        for i in range(1, len(ai)):
            ai[i][i] = g
        return (_fractions(self.c), _square(self.explicit), ai, _fractions(self.b),
                _fractions(self.bhat))

    def kernel_arrays(self):
        """What `_ark_step` takes: c, A_E, A_I left of the diagonal, b, b - bhat (float arrays), gamma.

        b - bhat is the difference of the rounded weights, so that the error
        estimate is exactly the difference of the two solutions as computed.
        """
        b, bhat = _fractions(self.b), _fractions(self.bhat)
        return (np.array(_fractions(self.c), dtype=float),
                np.array(_square(self.explicit), dtype=float),
                np.array(_square(self.implicit), dtype=float),
                np.array(b, dtype=float),
                np.array([float(p) - float(q) for p, q in zip(b, bhat)]),
                float(Fraction(self.gamma)))


def _fractions(xs):
    return [Fraction(x) for x in xs]


def _square(rows):
    """Strictly lower triangular square matrix (Fractions) from rows left of the diagonal."""
    s = len(rows)
    return [_fractions(row) + [Fraction(0)] * (s - len(row)) for row in rows]


# Kennedy & Carpenter (2003), Appl. Numer. Math. 44, 139, with the coefficients as SUNDIALS
# ARKODE ships them (ARK324L2SA_{ERK,DIRK}_4_2_3, ARK436L2SA_{ERK,DIRK}_6_3_4,
# ARK548L2SA_{ERK,DIRK}_8_4_5). Many are 13-digit rational approximations of irrational
# values; they satisfy the order conditions to about 1e-26, not exactly.
ARK324 = ArkPair(
    "ARK3(2)4L[2]SA", 3, 2,
    c=("0", "1767732205903/2027836641118", "3/5", "1"),
    explicit=((),
              ("1767732205903/2027836641118",),
              ("5535828885825/10492691773637", "788022342437/10882634858940"),
              ("6485989280629/16251701735622", "-4246266847089/9704473918619",
               "10755448449292/10357097424841")),
    implicit=((),
              ("1767732205903/4055673282236",),
              ("2746238789719/10658868560708", "-640167445237/6845629431997"),
              ("1471266399579/7840856788654", "-4482444167858/7529755066697",
               "11266239266428/11593286722821")),
    gamma="1767732205903/4055673282236",
    b=("1471266399579/7840856788654", "-4482444167858/7529755066697",
       "11266239266428/11593286722821", "1767732205903/4055673282236"),
    bhat=("2756255671327/12835298489170", "-10771552573575/22201958757719",
          "9247589265047/10645013368117", "2193209047091/5459859503100"))

ARK436 = ArkPair(
    "ARK4(3)6L[2]SA", 4, 3,
    c=("0", "1/2", "83/250", "31/50", "17/20", "1"),
    explicit=((),
              ("1/2",),
              ("13861/62500", "6889/62500"),
              ("-116923316275/2393684061468", "-2731218467317/15368042101831",
               "9408046702089/11113171139209"),
              ("-451086348788/2902428689909", "-2682348792572/7519795681897",
               "12662868775082/11960479115383", "3355817975965/11060851509271"),
              ("647845179188/3216320057751", "73281519250/8382639484533",
               "552539513391/3454668386233", "3354512671639/8306763924573", "4040/17871")),
    implicit=((),
              ("1/4",),
              ("8611/62500", "-1743/31250"),
              ("5012029/34652500", "-654441/2922500", "174375/388108"),
              ("15267082809/155376265600", "-71443401/120774400", "730878875/902184768",
               "2285395/8070912"),
              ("82889/524892", "0", "15625/83664", "69875/102672", "-2260/8211")),
    gamma="1/4",
    b=("82889/524892", "0", "15625/83664", "69875/102672", "-2260/8211", "1/4"),
    bhat=("4586570599/29645900160", "0", "178811875/945068544", "814220225/1159782912",
          "-3700637/11593932", "61727/225920"))

ARK548 = ArkPair(
    "ARK5(4)8L[2]SA", 5, 4,
    c=("0", "41/100", "2935347310677/11292855782101", "1426016391358/7196633302097", "92/100",
       "24/100", "3/5", "1"),
    explicit=((),
              ("41/100",),
              ("367902744464/2072280473677", "677623207551/8224143866563"),
              ("1268023523408/10340822734521", "0", "1029933939417/13636558850479"),
              ("14463281900351/6315353703477", "0", "66114435211212/5879490589093",
               "-54053170152839/4284798021562"),
              ("14090043504691/34967701212078", "0", "15191511035443/11219624916014",
               "-18461159152457/12425892160975", "-281667163811/9011619295870"),
              ("19230459214898/13134317526959", "0", "21275331358303/2942455364971",
               "-38145345988419/4862620318723", "-1/8", "-1/8"),
              ("-19977161125411/11928030595625", "0", "-40795976796054/6384907823539",
               "177454434618887/12078138498510", "782672205425/8267701900261",
               "-69563011059811/9646580694205", "7356628210526/4942186776405")),
    implicit=((),
              ("41/200",),
              ("41/400", "-567603406766/11931857230679"),
              ("683785636431/9252920307686", "0", "-110385047103/1367015193373"),
              ("3016520224154/10081342136671", "0", "30586259806659/12414158314087",
               "-22760509404356/11113319521817"),
              ("218866479029/1489978393911", "0", "638256894668/5436446318841",
               "-1179710474555/5321154724896", "-60928119172/8023461067671"),
              ("1020004230633/5715676835656", "0", "25762820946817/25263940353407",
               "-2161375909145/9755907335909", "-211217309593/5846859502534",
               "-4269925059573/7827059040749"),
              ("-872700587467/9133579230613", "0", "0", "22348218063261/9555858737531",
               "-1143369518992/8141816002931", "-39379526789629/19018526304540",
               "32727382324388/42900044865799")),
    gamma="41/200",
    b=("-872700587467/9133579230613", "0", "0", "22348218063261/9555858737531",
       "-1143369518992/8141816002931", "-39379526789629/19018526304540",
       "32727382324388/42900044865799", "41/200"),
    bhat=("-975461918565/9796059967033", "0", "0", "78070527104295/32432590147079",
          "-548382580838/3424219808633", "-33438840321285/15594753105479",
          "3629800801594/4656183773603", "4035322873751/18575991585200"))

_C3, _AE3, _AI3, _B3, _D3, _G3 = ARK324.kernel_arrays()
_C5, _AE5, _AI5, _B5, _D5, _G5 = ARK548.kernel_arrays()
_C4, _AE4, _AI4, _B4, _D4, _G4 = ARK436.kernel_arrays()


@nb.njit(cache=True, inline="always")
def _implicit_state(rhs, hg, v, guess):
    """psi with psi - hg (exp(-psi) - max(v, 0)) = rhs, Newton from `guess`.

    The left side is increasing and concave in psi, so Newton's iterates reach
    the root from below after the first step and never overshoot it; after a
    step s the distance to the root is below s^2 / 2 (|f''| < f'), so the
    iteration ends once that is below 1e-16 (1 + |psi|), one exp earlier than
    waiting for a negligible step. The root lies above `target`, and far below
    it Newton only climbs by about 1 per iteration, so the guess is raised to
    at least `target`; NaN (a loud failure) if it has not converged.
    """
    target = rhs - hg * (v if v > 0.0 else 0.0)
    psi = max(guess, target)
    ex = math.exp(-psi)
    for _ in range(60):
        e = hg * ex
        step = (psi - e - target) / (1.0 + e)
        psi -= step
        if step * step <= 2e-16 * (1.0 + abs(psi)):
            return psi
        if abs(step) < 1e-3:
            # exp(-psi) from the previous one: exp(step) by Taylor (error < step^5 / 120)
            ex *= 1.0 + step * (1.0 + step * (0.5 + step * (1.0 / 6.0 + step / 24.0)))
        else:
            ex = math.exp(-psi)
    return math.nan


@nb.njit(cache=True, error_model="numpy", inline="always")
def _ark_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol, c, ae, ai, bw, bd, gamma):
    """One step of the IMEX pair (c, ae, ai, gamma; weights bw, error weights bd = b - bhat).

    Stage s: slip and velocity explicit from the earlier stages' rates, psi
    implicit (one scalar Newton per block) with diagonal gamma.
    """
    pw = 0.0
    ys = 0.0
    hg = h * gamma
    for s in range(c.shape[0]):
        for k in range(na):
            i = act[k]
            y = W[i, Y0]
            v = W[i, V0]
            r = W[i, P0]
            for j in range(s):
                y += h * ae[s, j] * W[i, ARK_V + j]
                v += h * ae[s, j] * W[i, ARK_A + j]
                r += h * ai[s, j] * W[i, ARK_G + j]
            W[i, YS] = y
            W[i, VS] = v
            if s == 0:
                W[i, PS] = r
            else:
                # Newton starts from the explicit guess with the previous stage's rate (in KP);
                # the stage's state rate follows from the solved equation without an exp
                # (the event kernel may redo a step with h = 0)
                psi = _implicit_state(r, hg, v, r + hg * W[i, KP])
                W[i, PS] = psi
                W[i, KP] = (psi - r) / hg if hg > 0.0 else state_rate(v, psi)
        power, ysum = stage_rates(W, act, na, n, tau + c[s] * h, l2, nu, a, b, yrest, s == 0)
        pw += bw[s] * power
        ys += bw[s] * ysum
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
        for s in range(c.shape[0]):
            dy += bw[s] * W[i, ARK_V + s]
            dv += bw[s] * W[i, ARK_A + s]
            dp += bw[s] * W[i, ARK_G + s]
            ey += bd[s] * W[i, ARK_V + s]
            ev += bd[s] * W[i, ARK_A + s]
            ep += bd[s] * W[i, ARK_G + s]
        W[i, Y] = W[i, Y0] + h * dy
        W[i, V] = W[i, V0] + h * dv
        W[i, P] = W[i, P0] + h * dp
        W[i, YS] = W[i, Y]
        # slip and psi scales are at least 1: a block that just started must not
        # be held to the relative accuracy of its own vanishing slip (velocity
        # stays relative: a nucleating block's slow start decides the event)
        e1 = abs(h * ey) / (atol + rtol * max(abs(W[i, Y0]), abs(W[i, Y]), 1.0))
        e2 = abs(h * ev) / (atol + rtol * max(abs(W[i, V0]), abs(W[i, V])))
        e3 = abs(h * ep) / (atol + rtol * max(abs(W[i, P0]), abs(W[i, P]), 1.0))
        err = max(err, e1, e2, e3)
    return pw * h, ys * h, err


@nb.njit(cache=True, error_model="numpy")
def ark3_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol):
    """ARK3(2)4L[2]SA step of the active blocks; see the module docstring."""
    return _ark_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol,
                     _C3, _AE3, _AI3, _B3, _D3, _G3)


@nb.njit(cache=True, error_model="numpy")
def ark4_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol):
    """ARK4(3)6L[2]SA step of the active blocks; see the module docstring."""
    return _ark_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol,
                     _C4, _AE4, _AI4, _B4, _D4, _G4)


@nb.njit(cache=True, error_model="numpy")
def ark5_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol):
    """ARK5(4)8L[2]SA step of the active blocks; see the module docstring."""
    return _ark_step(W, act, na, n, tau, h, l2, nu, a, b, yrest, rtol, atol,
                     _C5, _AE5, _AI5, _B5, _D5, _G5)
