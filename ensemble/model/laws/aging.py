"""The paper's law: rate- and state-dependent friction with the aging law (Ohmura & Kawamura 2007).

    Phi = c + a ln(1 + v) + b ln(theta),   theta' = 1 - v theta

In the kernels' frame c is removed (w = u + c) and the state is psi = ln(theta), so the dynamic
friction is a ln(1 + v) + b psi, the static threshold of a block at rest is b psi, the state
relaxes while sliding at rate 1/theta = exp(-psi) (the stiff part, implicit in the ARK methods)
and grows at rest as theta + t. The loader moves at nu during events.
"""
import math
from collections import namedtuple

import numba as nb

from .. import onset
from ..workspace import IM_EXP, IM_RHS, IM_TARGET, IM_UNSOLVED, KP, PS, VS
from . import Key, Law, Scales

AgingParams = namedtuple("AgingParams", "a b")


@nb.njit(cache=True, inline="always")
def friction(law, v, psi):
    """a ln(1 + v) + b psi, at max(v, 0): an intermediate Runge-Kutta stage can see v < 0 (even
    v < -1, where ln(1 + v) is NaN); the physical velocity is never negative."""
    vp = v if v > 0.0 else 0.0
    if law.a != 0.0:
        return law.a * math.log1p(vp) + law.b * psi
    return law.b * psi


@nb.njit(cache=True, inline="always")
def threshold(law, psi):
    return law.b * psi


@nb.njit(cache=True, inline="always")
def state_rate(law, v, psi):
    """d psi / dt = 1/theta - v (v clamped at 0)."""
    vp = v if v > 0.0 else 0.0
    return math.exp(-psi) - vp


@nb.njit(cache=True, inline="always")
def rest_state(law, psi, dt):
    """ln(theta + dt), as psi + log1p(dt / theta) (onset.grow_state)."""
    return psi + math.log1p(dt * math.exp(-psi))


@nb.njit(cache=True, inline="always")
def onset_delay(law, force, psi, nu):
    """The root of F + nu t = b ln(theta + t) (onset.py: Lambert W by Newton)."""
    return onset.onset_delay(force, psi, nu, law.b)


@nb.njit(cache=True, inline="always")
def linear_state(law, v):
    """theta' = 1 - v theta (v clamped at 0): source 1, rate v."""
    return 1.0, (v if v > 0.0 else 0.0)


@nb.njit(cache=True, inline="always")
def creep_weakening(law, v, psi):
    """-b d(psi')/dv = b at every state: a cluster creeps while K_C - b I is positive definite
    (docs/numerics.md)."""
    return law.b


@nb.njit(cache=True, inline="always")
def friction_slopes(law, v, psi):
    """(a / (1 + v), b) at max(v, 0)."""
    vp = v if v > 0.0 else 0.0
    return law.a / (1.0 + vp), law.b


@nb.njit(cache=True)
def creep_state(law, psi0, v, h):
    """Backward Euler of psi' = exp(-psi) - v over h: psi - h exp(-psi) = psi0 - h v (the root lies
    above the right side; _newton_state), and d psi / d v = -h / (1 + h exp(-psi)). The first guess
    is the exact state for v held over the step, theta = 1/v + (theta0 - 1/v) exp(-v h)."""
    vp = v if v > 0.0 else 0.0
    target = psi0 - h * vp
    theta0 = math.exp(psi0)
    z = vp * h
    if z > 1e-8:
        theta = 1.0 / vp + (theta0 - 1.0 / vp) * math.exp(-z)
    else:
        theta = theta0 + h * (1.0 - vp * theta0)
    guess = math.log(theta) if theta > 0.0 else target
    psi = _newton_state(max(guess, target), target, h)
    return psi, (-h / (1.0 + h * math.exp(-psi)) if v > 0.0 else 0.0)


@nb.njit(cache=True, inline="always")
def stiff_limit(law, rate_limit):
    """The state relaxes at rate exp(-psi): RK4 needs psi > -ln(RK4_STABILITY / dt)."""
    return -math.log(rate_limit)


@nb.njit(cache=True, inline="always")
def rk4_unstable(law, v, psi, rate_limit, state_limit):
    """v and exp(-psi) are the rates of the state's relaxation (equal in steady sliding)."""
    return v > rate_limit or psi < state_limit


# The implicit stage equation of every block: psi - hg (exp(-psi) - max(v, 0)) = r. With
# target = r - hg max(v, 0) it reads psi - hg exp(-psi) = target, whose left side is increasing
# and concave in psi, so Newton's iterates reach the root from below after the first step and
# never overshoot it; after a step s the distance to the root is below s^2 / 2 (|f''| < f'), so
# a solve ends once that is below 1e-16 (1 + |psi|), one exp earlier than waiting for a
# negligible step. The root lies above `target`, and far below it Newton only climbs by about 1
# per iteration, so solves start at or above `target`.


@nb.njit(cache=True, inline="always")
def implicit_state(law, W, act, na, hg):
    """Solve the implicit stage for the active blocks: on entry W[i, PS] holds the right side r
    and W[i, VS] the stage velocity, W[i, KP] the previous stage's state rate; on return PS is
    the stage's psi and KP its state rate. Uses the IM_* columns (workspace.py) as scratch."""
    for k in range(na):
        i = act[k]
        r = W[i, PS]
        v = W[i, VS]
        # the solve starts from the explicit guess with the previous stage's rate, raised to at
        # least the root's lower bound `target`
        target = r - hg * (v if v > 0.0 else 0.0)
        W[i, PS] = max(r + hg * W[i, KP], target)
        W[i, IM_TARGET] = target
        W[i, IM_RHS] = r
    # the blocks' exps are independent: one pass for all of them keeps them out of each
    # solve's chain of dependent operations (~10% less time per step on large events)
    for k in range(na):
        i = act[k]
        W[i, IM_EXP] = math.exp(-W[i, PS])
    unsolved = False
    for k in range(na):
        i = act[k]
        psi, converged = _two_steps(W[i, PS], W[i, IM_EXP], W[i, IM_TARGET], hg)
        W[i, PS] = psi
        W[i, IM_UNSOLVED] = 0.0 if converged else 1.0
        unsolved |= not converged
    if unsolved:
        for k in range(na):
            i = act[k]
            if W[i, IM_UNSOLVED] != 0.0:
                W[i, PS] = _newton_state(W[i, PS], W[i, IM_TARGET], hg)
    for k in range(na):
        i = act[k]
        # the stage's state rate from the solved equation, without an exp (the event kernel may
        # redo a step with h = 0)
        psi = W[i, PS]
        W[i, KP] = (psi - W[i, IM_RHS]) / hg if hg > 0.0 else state_rate(law, W[i, VS], psi)


@nb.njit(cache=True, inline="always")
def _exp_taylor(x):
    """exp(x) by its Taylor polynomial of degree 6: relative error < x^7 / 5040 (< 2e-18 for |x| < 1e-2)."""
    return 1.0 + x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x / 720.0)))))


@nb.njit(cache=True, inline="always")
def _two_steps(psi, ex, target, hg):
    """(psi, converged): a Halley then a Newton step from psi with ex = exp(-psi), the usual case.

    Halley (f'' = -hg exp(-psi)) converges cubically, so the pair solves to
    round-off from guesses up to ~3e-3 off (two Newton steps: ~3e-4); the
    fallback then takes 6% of ark4's and 15% of ark5's solves on large events.
    The exp after the first step comes from Taylor, valid while that step is
    below 1e-2; `converged` says whether both held.
    """
    e = hg * ex
    f = psi - e - target
    d = 1.0 + e
    step1 = f * d / (d * d + 0.5 * f * e)
    psi -= step1
    ex *= _exp_taylor(step1)
    e = hg * ex
    step = (psi - e - target) / (1.0 + e)
    psi -= step
    return psi, abs(step1) < 1e-2 and step * step <= 2e-16 * (1.0 + abs(psi))


@nb.njit(cache=True)
def _newton_state(psi, target, hg):
    """Newton from psi until converged (the rare case); NaN, a loud failure, if it does not.

    Not inlined: the rare case stays out of the stage loop.
    """
    ex = math.exp(-psi)
    for _ in range(60):
        e = hg * ex
        step = (psi - e - target) / (1.0 + e)
        psi -= step
        if step * step <= 2e-16 * (1.0 + abs(psi)):
            return psi
        if abs(step) < 1e-2:
            ex *= _exp_taylor(step)
        else:
            ex = math.exp(-psi)
    return math.nan


LAW = Law(
    name="aging",
    params=AgingParams,
    keys={
        "a": Key(0.0, "model force", lambda x: x >= 0, ">= 0", "velocity-strengthening coefficient of a ln(1 + v)"),
        "b": Key(20.0, "model force", lambda x: x > 0, "> 0",
                 "state coefficient of b ln(theta) (slip weakening of slope b)"),
        "c": Key(1000.0, "model force", math.isfinite, "finite",
                 "constant friction (removed exactly by a uniform shift of u)"),
    },
    convention="rate- and state-dependent friction c + a ln(1 + v) + b ln(theta) with the aging law "
               "theta' = 1 - v theta (Ohmura & Kawamura, EPL 77, 69001, 2007); a block at rest holds while "
               "its force is at most c + b ln(theta); the loader moves at nu during events",
    has_state=True, loader_moves=True,
    friction=friction, threshold=threshold, state_rate=state_rate, rest_state=rest_state,
    onset_delay=onset_delay, implicit_state=implicit_state, stiff_limit=stiff_limit,
    rk4_unstable=rk4_unstable, linear_state=linear_state,
    creep_weakening=creep_weakening, creep_state=creep_state, friction_slopes=friction_slopes,
    steady_weakening="b",
    # the paper's axes: R(mu) over 0..7, large events mu >= 4, GR fit above 3, T nu up to 2000
    scales=Scales(mu_bins="0:7:70", mu_c=4.0, b_cut=3.0, tnu_bins="0:2000:80"),
    # exponential in the state: at rtol 1e-4 its magnitudes and recurrence times are those of ark4 at rtol 1e-7
    # (1e5 events per point at b = 20 and 50, N = 800), 1.3-1.5x faster than ark4 at rtol 1e-4 (docs/benchmarks.md)
    method="exp4")
