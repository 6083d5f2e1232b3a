"""The lattice: nx x ny blocks on a square lattice (a fault plane), nx along strike and ny across it, each on the
loader's spring (stiffness 1) and joined to its four nearest neighbours by springs of stiffness l^2 along strike and
l_y^2 across it, free edges (a missing neighbour is the block itself, as at the chain's free ends).

Block i sits at x = i % nx along strike, y = i // nx across it. The force on it (c-free frame, as the chain's):

    F_i = F0 + nu tau - y_i + l^2 (y_right - 2 y_i + y_left) + l_y^2 (y_up - 2 y_i + y_down)

With ny = 1 every across-strike term is exactly +0.0 (a missing neighbour's slip is the block's own), so the lattice
of one row computes the chain's numbers bit for bit; its creep clusters are then runs, solved by the chain's own
tridiagonal algorithms (the same operations), and a plane's clusters by banded elimination in index order
(`_band_*`, the band as wide as the cluster is along strike).
"""
from collections import namedtuple

import numba as nb
import numpy as np

from ..workspace import CR_DIAG, CR_DU, CR_EP, CR_H, CR_RES, CR_UPPER, CR_W, F0, UNTOUCHED, Y
from ..interpolant import slip_at
from . import Geometry, member
from . import chain


class LatticeParams(namedtuple("LatticeParams", "nx ny l2 l2y")):
    """The lattice's record for the kernels: nx blocks along strike, ny across, the springs l2 = l^2 along strike
    and l2y = l_y^2 across it (relative to the loader's)."""
    __slots__ = ()


@nb.njit(cache=True)
def left(g, i):
    return i - 1 if i % g.nx > 0 else i


@nb.njit(cache=True)
def right(g, i):
    return i + 1 if i % g.nx < g.nx - 1 else i


@nb.njit(cache=True)
def down(g, i):
    return i - g.nx if i >= g.nx else i


@nb.njit(cache=True)
def up(g, i, n):
    return i + g.nx if i + g.nx < n else i


@nb.njit(cache=True, inline="always")
def _force(F0_, tau, nu, l2, l2y, yl, y, yr, yd, yu):
    return F0_ + nu * tau - y + l2 * (yr - 2.0 * y + yl) + l2y * (yu - 2.0 * y + yd)


@nb.njit(cache=True, inline="always")
def spring_force(g, W, col, i, n, F0_, tau, nu):
    return _force(F0_, tau, nu, g.l2, g.l2y, W[left(g, i), col], W[i, col], W[right(g, i), col],
                  W[down(g, i), col], W[up(g, i, n), col])


@nb.njit(cache=True)
def spring_force_at(g, W, flag, x, i, n, F0_, tau, nu):
    yl = slip_at(W, flag, left(g, i), x)
    yr = slip_at(W, flag, right(g, i), x)
    yd = slip_at(W, flag, down(g, i), x)
    yu = slip_at(W, flag, up(g, i, n), x)
    return _force(F0_, tau, nu, g.l2, g.l2y, yl, W[i, Y], yr, yd, yu)


@nb.njit(cache=True)
def neighbours(g, i, n):
    return left(g, i), right(g, i), down(g, i), up(g, i, n)


@nb.njit(cache=True)
def around(g, i, n):
    return left(g, i), i, right(g, i), down(g, i), up(g, i, n)


@nb.njit(cache=True)
def _degrees(g, i, n):
    """(springs along strike, springs across) of block i."""
    x = i % g.nx
    along = (1.0 if x > 0 else 0.0) + (1.0 if x < g.nx - 1 else 0.0)
    across = (1.0 if i >= g.nx else 0.0) + (1.0 if i + g.nx < n else 0.0)
    return along, across


@nb.njit(cache=True)
def stiffness(g, i, n):
    """K_ii: the loader's spring, l^2 per neighbour along strike, l_y^2 per neighbour across."""
    along, across = _degrees(g, i, n)
    return 1.0 + g.l2 * along + g.l2y * across


@nb.njit(cache=True)
def coupling(g, i, j):
    return g.l2y if abs(i - j) == g.nx else g.l2


@nb.njit(cache=True)
def along(g, i):
    return i % g.nx


@nb.njit(cache=True)
def across(g, i):
    return i // g.nx


@nb.njit(cache=True)
def drop_stiffness(g, W, i, n):
    out_x = 0
    for j in (left(g, i), right(g, i)):
        if j != i and not W[j, Y] > 0.0:
            out_x += 1
    out_y = 0
    for j in (down(g, i), up(g, i, n)):
        if j != i and not W[j, Y] > 0.0:
            out_y += 1
    return 1.0 + g.l2 * out_x + g.l2y * out_y


@nb.njit(cache=True)
def spring_energy(g, W, flag, i, n, stored, y):
    """The springs to the right and up always, to the left and down if that block is untouched (the chain's
    order: right, then left; then up, then down)."""
    j = right(g, i)
    if j != i:
        stored += 0.5 * g.l2 * (W[j, Y] - y) ** 2
    j = left(g, i)
    if j != i and flag[j] == UNTOUCHED:
        stored += 0.5 * g.l2 * (y - W[j, Y]) ** 2
    j = up(g, i, n)
    if j != i:
        stored += 0.5 * g.l2y * (W[j, Y] - y) ** 2
    j = down(g, i)
    if j != i and flag[j] == UNTOUCHED:
        stored += 0.5 * g.l2y * (y - W[j, Y]) ** 2
    return stored


@nb.njit(cache=True)
def max_stiffness(g, n):
    """The stiffest block's K_ii: one with as many neighbours as the lattice has room for."""
    x = min(1, g.nx - 1)
    y = min(1, g.ny - 1)
    return stiffness(g, y * g.nx + x, n)


# -- clusters: connected sets of blocks, found by a walk; a plane's solved by banded elimination in index order

@nb.njit(cache=True)
def cluster(g, C, flag, kind, n, j, out, seen):
    """The connected blocks around j that are members of kind (j counted) into out[:m] in increasing order, each
    marked in seen (the caller clears it); returns m. A walk over out as its queue."""
    out[0] = j
    seen[j] = 1
    m = 1
    k = 0
    while k < m:
        i = out[k]
        k += 1
        for q in neighbours(g, i, n):
            if seen[q] == 0 and member(C, flag, kind, q):
                seen[q] = 1
                out[m] = q
                m += 1
    out[:m].sort()
    return m


@nb.njit(cache=True)
def _as_chain(g):
    return chain.ChainParams(g.l2)


@nb.njit(cache=True)
def _band_of(g, lst, m, n):
    """(pos, bw): each block's position in the cluster lst[:m] (pos[i], -1 outside it) and the band's half
    width in positions (the farthest neighbour in the list: at most nx)."""
    pos = np.full(n, -1, dtype=np.int64)
    for k in range(m):
        pos[lst[k]] = k
    bw = 1
    for k in range(m):
        i = lst[k]
        for q in neighbours(g, i, n):
            if q != i and pos[q] >= 0:
                bw = max(bw, abs(pos[q] - k))
    return pos, bw


@nb.njit(cache=True)
def _band_solve(B, rhs, m, bw, sign):
    """Gaussian elimination without pivoting of the band matrix B (row k: columns k - bw .. k + bw at B[k, 0 ..
    2 bw]) and the right-hand side rhs in place, rows in order; returns -1, or the first row whose pivot does not
    have the sign `sign` (then nothing is solved). The pivots stay on B's diagonal B[k, bw]."""
    for k in range(m):
        for q in range(max(0, k - bw), k):
            a = B[k, q - k + bw]
            if a != 0.0:
                mult = a / B[q, bw]
                for c in range(q + 1, min(q + bw, m - 1) + 1):
                    B[k, c - k + bw] -= mult * B[q, c - q + bw]
                rhs[k] -= mult * rhs[q]
                B[k, q - k + bw] = 0.0
        if not sign * B[k, bw] > 0.0:
            return k
    for k in range(m - 1, -1, -1):
        r = rhs[k]
        for c in range(k + 1, min(k + bw, m - 1) + 1):
            r -= B[k, c - k + bw] * rhs[c]
        rhs[k] = r / B[k, bw]
    return -1


@nb.njit(cache=True)
def _stiffness_band(g, C, lst, m, n, diag_less, scale_by_h):
    """The cluster's K_C - diag(diag_less) as a band (scale_by_h: each column j times C[j, CR_H], the creep's
    Jacobian J = -(K_C + ...) H, whose diagonal the caller sets), its positions and half width."""
    pos, bw = _band_of(g, lst, m, n)
    B = np.zeros((m, 2 * bw + 1))
    for k in range(m):
        i = lst[k]
        B[k, bw] = stiffness(g, i, n) - diag_less[k]
        for q in neighbours(g, i, n):
            if q != i and pos[q] >= 0:
                B[k, pos[q] - k + bw] = -coupling(g, i, q) * (C[q, CR_H] if scale_by_h else 1.0)
    return B, bw


@nb.njit(cache=True)
def stable(g, C, n, lst, m):
    """K_C - diag(C[lst, CR_W]) is positive definite: every pivot of its elimination positive."""
    if g.ny == 1:
        return chain.stable(_as_chain(g), C, n, lst, m)
    less = np.empty(m)
    for k in range(m):
        less[k] = C[lst[k], CR_W]
    B, bw = _stiffness_band(g, C, lst, m, n, less, False)
    return _band_solve(B, np.zeros(m), m, bw, 1.0) < 0


@nb.njit(cache=True)
def fastest_creep(g, C, n, nu, lst, m):
    """C[lst, CR_RES] = (K_C - diag(max(CR_W, 0)))^-1 nu 1 for the stable cluster lst[:m]."""
    if g.ny == 1:
        chain.fastest_creep(_as_chain(g), C, n, nu, lst, m)
        return
    less = np.empty(m)
    for k in range(m):
        less[k] = max(C[lst[k], CR_W], 0.0)
    B, bw = _stiffness_band(g, C, lst, m, n, less, False)
    rhs = np.full(m, nu)
    _band_solve(B, rhs, m, bw, 1.0)
    for k in range(m):
        C[lst[k], CR_RES] = rhs[k]


@nb.njit(cache=True, inline="always")
def _creeping(C, i):
    return C[i, CR_EP] != 0.0


@nb.njit(cache=True, inline="always")
def _creep_slip(C, i, j):
    """A creep step's slip CR_DU of neighbour j of block i if it creeps (0 if it does not or is missing)."""
    return C[j, CR_DU] if j != i and _creeping(C, j) else 0.0


@nb.njit(cache=True)
def creep_force(g, C, W, i, n, nu, h):
    """The force on creeping block i after its creep step h, its creeping neighbours' slips CR_DU in."""
    du_l = _creep_slip(C, i, left(g, i))
    du_r = _creep_slip(C, i, right(g, i))
    du_d = _creep_slip(C, i, down(g, i))
    du_u = _creep_slip(C, i, up(g, i, n))
    return W[i, F0] + nu * h - stiffness(g, i, n) * C[i, CR_DU] + g.l2 * (du_l + du_r) + g.l2y * (du_d + du_u)


@nb.njit(cache=True)
def creep_load(g, C, j, n, x):
    """The force on resting block j from x of its creeping neighbours' slips CR_DU."""
    slip_x = 0.0
    for k in (left(g, j), right(g, j)):
        if k != j and _creeping(C, k):
            slip_x += C[k, CR_DU]
    slip_y = 0.0
    for k in (down(g, j), up(g, j, n)):
        if k != j and _creeping(C, k):
            slip_y += C[k, CR_DU]
    return g.l2 * x * slip_x + g.l2y * x * slip_y


@nb.njit(cache=True)
def creep_solve(g, C, lst, m, n):
    """The creep's Newton update of every creeping block lst[:m] (geometry/__init__.py): J = CR_DIAG on the
    diagonal, K_ij h_j off it, over each cluster (the creeping blocks' band: clusters apart are not coupled)."""
    if g.ny == 1:
        return chain.creep_solve(_as_chain(g), C, lst, m, n)
    less = np.zeros(m)
    B, bw = _stiffness_band(g, C, lst, m, n, less, True)
    rhs = np.empty(m)
    for k in range(m):
        i = lst[k]
        B[k, bw] = C[i, CR_DIAG]
        rhs[k] = C[i, CR_RES]
    for k in range(m):
        for c in range(2 * bw + 1):
            if c != bw:
                B[k, c] = -B[k, c]      # J[i, j] = +K_ij h_j (the band holds -K_ij h_j)
    bad = _band_solve(B, rhs, m, bw, -1.0)
    if bad >= 0:
        return lst[bad]
    for k in range(m):
        i = lst[k]
        C[i, CR_DIAG] = B[k, bw]
        C[i, CR_UPPER] = rhs[k]
    return -1


def _record(model):
    return LatticeParams(nx=int(model.N), ny=int(model.M), l2=float(model.l) ** 2, l2y=float(model.l_across) ** 2)


GEOMETRY = Geometry("lattice", LatticeParams, _record, spring_force, spring_force_at, neighbours, around, stiffness,
                    coupling, along, across, drop_stiffness, spring_energy, max_stiffness, cluster, stable,
                    fastest_creep, creep_force, creep_load, creep_solve)
