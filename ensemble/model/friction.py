"""The friction law, the chain's geometry and the equation of motion of one sliding block.

This module is the only place to change for another friction law: the event
integrators call `acceleration` and `state_rate` and nothing else of the law.
Frame: c is removed exactly by the shift w = u + c, so friction here is
a ln(1 + v) + b psi with psi = ln(theta); the static threshold is b psi.
"""
import math

import numba as nb


@nb.njit(cache=True, inline="always")
def friction(v, psi, a, b):
    """Dynamic friction a ln(1 + v) + b psi, evaluated at max(v, 0).

    An intermediate Runge-Kutta stage can see v < 0 (even v < -1, where
    ln(1 + v) is NaN); the physical velocity is never negative.
    """
    vp = v if v > 0.0 else 0.0
    if a != 0.0:
        return a * math.log1p(vp) + b * psi
    return b * psi


@nb.njit(cache=True, inline="always")
def state_rate(v, psi):
    """d psi / dt = 1/theta - v for the aging law theta' = 1 - v theta (v clamped at 0)."""
    vp = v if v > 0.0 else 0.0
    return math.exp(-psi) - vp


@nb.njit(cache=True, inline="always")
def left(i):
    """Left neighbour of block i; at the free end the block itself (ghost u_{-1} = u_0)."""
    return i - 1 if i > 0 else i


@nb.njit(cache=True, inline="always")
def right(i, n):
    """Right neighbour of block i in a chain of n; at the free end the block itself."""
    return i + 1 if i < n - 1 else i


@nb.njit(cache=True, inline="always")
def spring_force(F0, tau, nu, l2, y_left, y_mid, y_right):
    """Force on a block at local time tau after the event started.

    F0 is the block's force at the start of the event (c-free frame), y_* the
    slips since the start of the event of the block and its two neighbours
    (at a free end the missing neighbour is the block itself).
    """
    return F0 + nu * tau - y_mid + l2 * (y_right - 2.0 * y_mid + y_left)
