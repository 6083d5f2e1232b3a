"""The chain: N blocks in a line, each on the loader's spring (stiffness 1) and joined to its two neighbours by
springs of stiffness l^2, free ends (a missing neighbour is the block itself: the ghost u_{-1} = u_0).

Frame: forces without constant friction (the aging law's c is removed exactly by the shift w = u + c), so a
block's force is compared with its law's threshold (laws/__init__.py).
"""
from collections import namedtuple

import numba as nb

from ..workspace import UNTOUCHED, Y
from . import Geometry


class ChainParams(namedtuple("ChainParams", "l2")):
    """The chain's record for the kernels: l2 = l^2, the springs between neighbours relative to the loader's."""
    __slots__ = ()


@nb.njit(cache=True, inline="always")
def left(i):
    """Left neighbour of block i; at the free end the block itself (ghost u_{-1} = u_0)."""
    return i - 1 if i > 0 else i


@nb.njit(cache=True, inline="always")
def right(i, n):
    """Right neighbour of block i in a chain of n; at the free end the block itself."""
    return i + 1 if i < n - 1 else i


@nb.njit(cache=True, inline="always")
def spring_force_of(F0, tau, nu, l2, y_left, y_mid, y_right):
    """Force on a block at local time tau after the event started.

    F0 is the block's force at the start of the event (c-free frame), y_* the
    slips since the start of the event of the block and its two neighbours
    (at a free end the missing neighbour is the block itself).
    """
    return F0 + nu * tau - y_mid + l2 * (y_right - 2.0 * y_mid + y_left)


@nb.njit(cache=True, inline="always")
def spring_force(g, W, col, i, n, F0, tau, nu):
    """The geometry's spring_force (geometry/__init__.py) on the chain."""
    return spring_force_of(F0, tau, nu, g.l2, W[left(i), col], W[i, col], W[right(i, n), col])


@nb.njit(cache=True, inline="always")
def spring_force_by(g, slip, W, flag, x, i, n, F0, tau, nu):
    yl = slip(W, flag, left(i), x)
    yr = slip(W, flag, right(i, n), x)
    return spring_force_of(F0, tau, nu, g.l2, yl, W[i, Y], yr)


@nb.njit(cache=True, inline="always")
def neighbours(g, i, n):
    return left(i), right(i, n)


@nb.njit(cache=True, inline="always")
def around(g, i, n):
    return left(i), i, right(i, n)


@nb.njit(cache=True, inline="always")
def stiffness(g, i, n):
    """K_ii: the loader's spring and one or two of l^2."""
    return 1.0 + g.l2 * ((1.0 if i > 0 else 0.0) + (1.0 if i < n - 1 else 0.0))


@nb.njit(cache=True, inline="always")
def coupling(g, i, j):
    return g.l2


@nb.njit(cache=True, inline="always")
def along(g, i):
    return i


@nb.njit(cache=True, inline="always")
def drop_stiffness(g, W, i, n):
    outside = (1 if i > 0 and not W[i - 1, Y] > 0.0 else 0) + (1 if i < n - 1 and not W[i + 1, Y] > 0.0 else 0)
    return 1.0 + g.l2 * outside


@nb.njit(cache=True, inline="always")
def spring_energy(g, W, flag, i, n, stored, y):
    """The spring to the right always (its right block's own sum never counts it), to the left if that block is
    untouched (else its sum counted it)."""
    if i + 1 < n:
        stored += 0.5 * g.l2 * (W[i + 1, Y] - y) ** 2
    if i - 1 >= 0 and flag[i - 1] == UNTOUCHED:
        stored += 0.5 * g.l2 * (y - W[i - 1, Y]) ** 2
    return stored


def _record(model):
    return ChainParams(l2=float(model.l) ** 2)


GEOMETRY = Geometry("chain", ChainParams, _record, spring_force, spring_force_by, neighbours, around, stiffness,
                    coupling, along, drop_stiffness, spring_energy)
