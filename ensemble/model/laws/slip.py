"""Ruina's slip law: rate- and state-dependent friction whose state evolves only with slip.

    Phi = c + a ln(1 + v) + b ln(theta),   psi' = -v (psi + ln v)   (psi = ln theta)

The friction is the aging law's (aging.py; in the kernels' frame c is removed and the dynamic
friction is a ln(1 + v) + b psi), and so is the steady state psi = -ln v. Only the state's
evolution differs: it changes only while a block slips, so a block at rest keeps its state and its
static threshold b psi (no healing at rest, Ruina 1983), and a loaded block with v theta < 1
strengthens as it slips. Every block that reaches its threshold therefore creeps first
(model/creep.py); it ruptures when its weakening outgrows its stiffness (the creep step's system
loses its negative pivots) or when its creep accelerates on inertia's time scale. Its weakening
per unit slip, -d psi / d u = ln(v theta), has no bound, so no stiffness keeps a loaded cluster
creeping for ever. The loader moves at nu during events.
"""
import math
from collections import namedtuple

import numba as nb

from ..workspace import KP, PS, VS
from . import Law
from .aging import LAW as AGING, friction, friction_slopes, threshold

SlipParams = namedtuple("SlipParams", "a b")

# Below this velocity the creep step's state is continued linearly in v (creep_state): ln v is
# singular at 0, and the creep step's Newton iteration starts from v = 0 and may need v < 0 to find
# that a block stops
V_FLOOR = 1e-300


@nb.njit(cache=True, inline="always")
def _v_ln_v(v):
    """v ln v at max(v, 0) (0 at v = 0, its limit)."""
    return v * math.log(v) if v > 0.0 else 0.0


@nb.njit(cache=True, inline="always")
def state_rate(law, v, psi):
    """d psi / dt = -v (psi + ln v) at max(v, 0)."""
    vp = v if v > 0.0 else 0.0
    return -(vp * psi + _v_ln_v(vp))


@nb.njit(cache=True, inline="always")
def rest_state(law, psi, dt):
    """No slip, no change of state."""
    return psi


@nb.njit(cache=True, inline="always")
def onset_delay(law, force, psi, nu):
    """The loader alone raises the force linearly to the constant threshold b psi."""
    gap = law.b * psi - force
    if gap <= 0.0:
        return 0.0
    return gap / nu


@nb.njit(cache=True)     # not inlined: inlined twice (here and by the law's call) it made numba warn
def creep_weakening(law, v, psi):
    """-b d(psi')/dv = b (psi + ln v + 1): strengthening (negative) while v theta < 1/e, -inf from rest,
    so every block starts by creeping; it has no bound, so no stiffness keeps a loaded cluster
    creeping for ever."""
    if v > 0.0:
        return law.b * (psi + math.log(v) + 1.0)
    return -math.inf


@nb.njit(cache=True)
def creep_state(law, psi0, v, h):
    """Backward Euler of psi' = -v (psi + ln v) over h, explicit: psi = (psi0 - h v ln v) / (1 + h v),
    d psi / d v = -h (ln v + 1 + psi) / (1 + h v); continued linearly below V_FLOOR."""
    vf = v if v > V_FLOOR else V_FLOOR
    psi = (psi0 - h * vf * math.log(vf)) / (1.0 + h * vf)
    dpsi = -h * (math.log(vf) + 1.0 + psi) / (1.0 + h * vf)
    if v < V_FLOOR:
        psi += dpsi * (v - V_FLOOR)
    return psi, dpsi


@nb.njit(cache=True, inline="always")
def implicit_state(law, W, act, na, hg):
    """The implicit stage psi - hg g(v, psi) = r is linear in psi: psi = (r - hg v ln v) / (1 + hg v)
    (W's columns as aging.implicit_state uses them)."""
    for k in range(na):
        i = act[k]
        r = W[i, PS]
        v = W[i, VS]
        vp = v if v > 0.0 else 0.0
        psi = (r - hg * _v_ln_v(vp)) / (1.0 + hg * vp)
        W[i, PS] = psi
        W[i, KP] = (psi - r) / hg if hg > 0.0 else state_rate(law, v, psi)


@nb.njit(cache=True, inline="always")
def stiff_limit(law, rate_limit):
    """The state's stiffness is v alone: no bound on the state."""
    return -math.inf


@nb.njit(cache=True, inline="always")
def rk4_unstable(law, v, psi, rate_limit, state_limit):
    """The state relaxes at rate v."""
    return v > rate_limit


LAW = Law(
    name="slip",
    params=SlipParams,
    keys=AGING.keys,        # a, b, c: one meaning each, shared with the aging law
    convention="rate- and state-dependent friction c + a ln(1 + v) + b ln(theta) with Ruina's slip law "
               "psi' = -v (psi + ln v), psi = ln(theta) (Ruina, JGR 88, 10359, 1983); a block at rest keeps its "
               "state and holds while its force is at most c + b ln(theta); a block that reaches it creeps "
               "quasi-statically until its creep becomes unstable; the loader moves at nu during events",
    has_state=True, loader_moves=True,
    friction=friction, threshold=threshold, state_rate=state_rate, rest_state=rest_state,
    onset_delay=onset_delay, implicit_state=implicit_state, stiff_limit=stiff_limit,
    rk4_unstable=rk4_unstable,
    creep_weakening=creep_weakening, creep_state=creep_state, friction_slopes=friction_slopes,
    steady_weakening="b",
    scales=AGING.scales)
