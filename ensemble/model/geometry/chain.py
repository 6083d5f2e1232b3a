"""The chain: N blocks in a line, each on the loader's spring (stiffness 1) and joined to its two neighbours by
springs of stiffness l^2, free ends (a missing neighbour is the block itself: the ghost u_{-1} = u_0).

Frame: forces without constant friction (the aging law's c is removed exactly by the shift w = u + c), so a
block's force is compared with its law's threshold (laws/__init__.py).
"""
from collections import namedtuple

import numba as nb

from ..workspace import CR_DIAG, CR_DU, CR_H, CR_RES, CR_UPPER, CR_W, F0, UNTOUCHED, Y
from ..interpolant import slip_at
from . import Geometry, creeping, member


class ChainParams(namedtuple("ChainParams", "l2")):
    """The chain's record for the kernels: l2 = l^2, the springs between neighbours relative to the loader's."""
    __slots__ = ()


@nb.njit(cache=True)
def left(i):
    """Left neighbour of block i; at the free end the block itself (ghost u_{-1} = u_0)."""
    return i - 1 if i > 0 else i


@nb.njit(cache=True)
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
def spring_force_at(g, W, flag, x, i, n, F0, tau, nu):
    yl = slip_at(W, flag, left(i), x)
    yr = slip_at(W, flag, right(i, n), x)
    return spring_force_of(F0, tau, nu, g.l2, yl, W[i, Y], yr)


@nb.njit(cache=True)
def neighbours(g, i, n):
    return left(i), right(i, n)


@nb.njit(cache=True)
def around(g, i, n):
    return left(i), i, right(i, n)


@nb.njit(cache=True)
def stiffness(g, i, n):
    """K_ii: the loader's spring and one or two of l^2."""
    return 1.0 + g.l2 * ((1.0 if i > 0 else 0.0) + (1.0 if i < n - 1 else 0.0))


@nb.njit(cache=True)
def coupling(g, i, j):
    return g.l2


@nb.njit(cache=True)
def along(g, i):
    return i


@nb.njit(cache=True)
def across(g, i):
    return 0


@nb.njit(cache=True)
def drop_stiffness(g, W, i, n):
    outside = (1 if i > 0 and not W[i - 1, Y] > 0.0 else 0) + (1 if i < n - 1 and not W[i + 1, Y] > 0.0 else 0)
    return 1.0 + g.l2 * outside


@nb.njit(cache=True)
def spring_energy(g, W, flag, i, n, stored, y):
    """The spring to the right always (its right block's own sum never counts it), to the left if that block is
    untouched (else its sum counted it)."""
    if i + 1 < n:
        stored += 0.5 * g.l2 * (W[i + 1, Y] - y) ** 2
    if i - 1 >= 0 and flag[i - 1] == UNTOUCHED:
        stored += 0.5 * g.l2 * (y - W[i - 1, Y]) ** 2
    return stored


@nb.njit(cache=True)
def max_stiffness(g, n):
    """The stiffest block's K_ii: an interior one's (an end's when n is 2, the loader's alone when 1)."""
    return stiffness(g, min(1, n - 1), n)


# -- clusters: a cluster of the chain is a run of neighbouring blocks lo..hi, its stiffness matrix tridiagonal

@nb.njit(cache=True)
def cluster(g, C, flag, kind, n, j, out, seen):
    """The run of blocks around j that are members of kind (j counted) into out[:m] in increasing order, each
    marked in seen (the caller clears it); returns m."""
    lo = j
    while lo > 0 and member(C, flag, kind, lo - 1):
        lo -= 1
    hi = j
    while hi < n - 1 and member(C, flag, kind, hi + 1):
        hi += 1
    for i in range(lo, hi + 1):
        out[i - lo] = i
        seen[i] = 1
    return hi - lo + 1


@nb.njit(cache=True)
def stable(g, C, n, lst, m):
    """K_C - diag(C[lst, CR_W]), the run's stiffness less each block's weakening, is positive definite (every
    pivot of its tridiagonal LDL^T factorisation positive)."""
    l2 = g.l2
    pivot = 1.0
    for k in range(m):
        i = lst[k]
        d = stiffness(g, i, n) - C[i, CR_W]
        if k > 0:
            d -= l2 * l2 / pivot
        if not d > 0.0:
            return False
        pivot = d
    return True


@nb.njit(cache=True)
def fastest_creep(g, C, n, nu, lst, m):
    """C[lst, CR_RES] = (K_C - diag(max(CR_W, 0)))^-1 nu 1 for the stable run lst[:m]: Thomas' algorithm, the
    pivots in CR_DIAG."""
    l2 = g.l2
    for k in range(m):
        i = lst[k]
        d = stiffness(g, i, n) - max(C[i, CR_W], 0.0)
        r = nu
        if k > 0:
            mult = -l2 / C[i - 1, CR_DIAG]
            d += mult * l2
            r -= mult * C[i - 1, CR_RES]
        C[i, CR_DIAG] = d
        C[i, CR_RES] = r
    hi = lst[m - 1]
    C[hi, CR_RES] /= C[hi, CR_DIAG]
    for k in range(m - 2, -1, -1):
        i = lst[k]
        C[i, CR_RES] = (C[i, CR_RES] + l2 * C[i + 1, CR_RES]) / C[i, CR_DIAG]


@nb.njit(cache=True)
def creep_force(g, C, W, i, n, nu, h):
    """The force on creeping block i at the end of its creep step h, its creeping neighbours' slips CR_DU in."""
    du_l = C[i - 1, CR_DU] if i > 0 and creeping(C, i - 1) else 0.0
    du_r = C[i + 1, CR_DU] if i < n - 1 and creeping(C, i + 1) else 0.0
    return W[i, F0] + nu * h - stiffness(g, i, n) * C[i, CR_DU] + g.l2 * (du_l + du_r)


@nb.njit(cache=True)
def creep_load(g, C, j, n, x):
    """The force on resting block j from x of its creeping neighbours' slips CR_DU."""
    slip = 0.0
    for k in (left(j), right(j, n)):
        if k != j and creeping(C, k):
            slip += C[k, CR_DU]
    return g.l2 * x * slip


@nb.njit(cache=True)
def creep_solve(g, C, lst, m, n):
    """The creep's Newton update of every creeping block (lst[:m], increasing): the Jacobian's diagonal in
    CR_DIAG, the residual in CR_RES; J[i, j] = l2 h_j between creeping neighbours. Its LDL^T by Thomas' forward
    sweep (the pivots into CR_DIAG, the reduced residual into CR_RES), the update into CR_UPPER. Returns -1, or
    the first block whose pivot is not negative (the system is no longer a creeping cluster's; nothing solved)."""
    l2 = g.l2
    for k in range(m):
        i = lst[k]
        if i > 0 and creeping(C, i - 1):
            mult = l2 * C[i - 1, CR_H] / C[i - 1, CR_DIAG]     # J[i, i-1] / pivot[i-1]
            C[i, CR_DIAG] -= mult * l2 * C[i, CR_H]             # J[i-1, i] = l2 h_i
            C[i, CR_RES] -= mult * C[i - 1, CR_RES]
        if not C[i, CR_DIAG] < 0.0:
            return i
    for k in range(m - 1, -1, -1):
        i = lst[k]
        r = C[i, CR_RES]
        if i < n - 1 and creeping(C, i + 1):
            r -= l2 * C[i + 1, CR_H] * C[i + 1, CR_UPPER]
        C[i, CR_UPPER] = r / C[i, CR_DIAG]
    return -1


def _record(model):
    return ChainParams(l2=float(model.l) ** 2)


GEOMETRY = Geometry("chain", ChainParams, _record, spring_force, spring_force_at, neighbours, around, stiffness,
                    coupling, along, across, drop_stiffness, spring_energy, max_stiffness, cluster, stable,
                    fastest_creep, creep_force, creep_load, creep_solve, grid=True)
