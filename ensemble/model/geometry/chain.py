"""The chain: N blocks in a line, each on the loader's spring (stiffness 1) and joined to its two neighbours by
springs of stiffness l^2, free ends (a missing neighbour is the block itself: the ghost u_{-1} = u_0).

Frame: forces without constant friction (the aging law's c is removed exactly by the shift w = u + c), so a
block's force is compared with its law's threshold (laws/__init__.py).
"""
from collections import namedtuple

import numba as nb

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


def _record(model):
    return ChainParams(l2=float(model.l) ** 2)


GEOMETRY = Geometry("chain", ChainParams, _record, spring_force)
