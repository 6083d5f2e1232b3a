"""What any geometry's blocks and springs imply, written once: a geometry that declares its neighbours, springs and
positions (`geometry()` below) gets the rest of the Geometry record from here.

Every function here reads the geometry through the package's calls (neighbours, stiffness, coupling of the record
g), so numba compiles it once per geometry, as a geometry's own functions. The forces sum the springs to the
neighbours in the order `neighbours` gives them; the creep phase's clusters are found by a walk over the neighbours
and solved by banded Gaussian elimination in index order (the band as wide as the farthest neighbour in the
cluster's list: w^3 h operations for a cluster of w x h blocks on a lattice, the cluster's size times its neighbours'
reach in general). The chain keeps its own, shorter arithmetic (geometry/chain.py), and the lattice its own forces
(geometry/lattice.py: one row of it is the chain bit for bit).
"""
import numba as nb
import numpy as np

from ..interpolant import slip_at
from ..workspace import CR_DIAG, CR_DU, CR_H, CR_RES, CR_UPPER, CR_W, F0, UNTOUCHED, Y
from . import Geometry, coupling, creeping, member, neighbours, stiffness


@nb.njit(cache=True)
def spring_force(g, W, col, i, n, F0, tau, nu):
    y = W[i, col]
    force = F0 + nu * tau - y
    for j in neighbours(g, i, n):
        if j != i:
            force += coupling(g, i, j) * (W[j, col] - y)
    return force


@nb.njit(cache=True)
def spring_force_at(g, W, flag, x, i, n, F0, tau, nu):
    y = W[i, Y]
    force = F0 + nu * tau - y
    for j in neighbours(g, i, n):
        if j != i:
            force += coupling(g, i, j) * (slip_at(W, flag, j, x) - y)
    return force


@nb.njit(cache=True)
def stiffness_times(g, x, out):
    """out = K x: the loader's spring and every spring of the geometry (the Python side's energy and physical
    state, ensemble/energy.py; any geometry, through its neighbours and springs)."""
    n = x.shape[0]
    for i in range(n):
        f = stiffness(g, i, n) * x[i]
        for j in neighbours(g, i, n):
            if j != i:
                f -= coupling(g, i, j) * x[j]
        out[i] = f


@nb.njit(cache=True)
def drop_stiffness(g, W, i, n):
    """1 and the springs from block i to neighbours that did not slip."""
    k = 1.0
    for j in neighbours(g, i, n):
        if j != i and not W[j, Y] > 0.0:
            k += coupling(g, i, j)
    return k


@nb.njit(cache=True)
def spring_energy(g, W, flag, i, n, stored, y):
    """Each spring of block i once over an event's touched blocks: to a higher neighbour always, to a lower one if
    that one is untouched (a touched lower neighbour counted it)."""
    for j in neighbours(g, i, n):
        if j != i and (j > i or flag[j] == UNTOUCHED):
            stored += 0.5 * coupling(g, i, j) * (W[j, Y] - y) ** 2
    return stored


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
def _band_of(g, lst, m, n):
    """(pos, bw): each block's position in the cluster lst[:m] (pos[i], -1 outside it) and the band's half
    width in positions (the farthest neighbour in the list)."""
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
    """The cluster's K_C - diag(diag_less) as a band (scale_by_h: each column j times C[j, CR_H]), and its half
    width."""
    pos, bw = _band_of(g, lst, m, n)
    B = np.zeros((m, 2 * bw + 1))
    for k in range(m):
        i = lst[k]
        B[k, bw] = stiffness(g, i, n) - diag_less[k]
        for q in neighbours(g, i, n):
            if q != i and pos[q] >= 0:
                B[k, pos[q] - k + bw] -= coupling(g, i, q) * (C[q, CR_H] if scale_by_h else 1.0)
    return B, bw


@nb.njit(cache=True)
def stable(g, C, n, lst, m):
    """K_C - diag(C[lst, CR_W]) is positive definite: every pivot of its elimination positive."""
    less = np.empty(m)
    for k in range(m):
        less[k] = C[lst[k], CR_W]
    B, bw = _stiffness_band(g, C, lst, m, n, less, False)
    return _band_solve(B, np.zeros(m), m, bw, 1.0) < 0


@nb.njit(cache=True)
def fastest_creep(g, C, n, nu, lst, m):
    """C[lst, CR_RES] = (K_C - diag(max(CR_W, 0)))^-1 nu 1 for the stable cluster lst[:m]."""
    less = np.empty(m)
    for k in range(m):
        less[k] = max(C[lst[k], CR_W], 0.0)
    B, bw = _stiffness_band(g, C, lst, m, n, less, False)
    rhs = np.full(m, nu)
    _band_solve(B, rhs, m, bw, 1.0)
    for k in range(m):
        C[lst[k], CR_RES] = rhs[k]


@nb.njit(cache=True)
def creep_solve(g, C, lst, m, n):
    """The creep's Newton update of every creeping block lst[:m] (geometry/__init__.py): J = CR_DIAG on the
    diagonal, K_ij h_j off it, over the creeping blocks' band (clusters apart are not coupled)."""
    B, bw = _stiffness_band(g, C, lst, m, n, np.zeros(m), True)
    rhs = np.empty(m)
    for k in range(m):
        i = lst[k]
        for c in range(2 * bw + 1):
            B[k, c] = -B[k, c]      # J[i, j] = +K_ij h_j (the band holds -K_ij h_j)
        B[k, bw] = C[i, CR_DIAG]
        rhs[k] = C[i, CR_RES]
    bad = _band_solve(B, rhs, m, bw, -1.0)
    if bad >= 0:
        return lst[bad]
    for k in range(m):
        i = lst[k]
        C[i, CR_DIAG] = B[k, bw]
        C[i, CR_UPPER] = rhs[k]
    return -1


@nb.njit(cache=True)
def creep_force(g, C, W, i, n, nu, h):
    """The force on creeping block i after its creep step h, its creeping neighbours' slips CR_DU in."""
    force = W[i, F0] + nu * h - stiffness(g, i, n) * C[i, CR_DU]
    for j in neighbours(g, i, n):
        if j != i and creeping(C, j):
            force += coupling(g, i, j) * C[j, CR_DU]
    return force


@nb.njit(cache=True)
def creep_load(g, C, j, n, x):
    """The force on resting block j from x of its creeping neighbours' slips CR_DU."""
    load = 0.0
    for k in neighbours(g, j, n):
        if k != j and creeping(C, k):
            load += coupling(g, j, k) * C[k, CR_DU]
    return x * load


def geometry(name, params, record, *, neighbours, around, stiffness, coupling, along, across, max_stiffness,
             keys=(), **own):
    """A Geometry of these neighbours and springs, the rest from here (a geometry's own functions in `own`)."""
    parts = dict(spring_force=spring_force, spring_force_at=spring_force_at, drop_stiffness=drop_stiffness,
                 spring_energy=spring_energy, cluster=cluster, stable=stable, fastest_creep=fastest_creep,
                 creep_force=creep_force, creep_load=creep_load, creep_solve=creep_solve)
    parts.update(own)
    return Geometry(name, params, record, neighbours=neighbours, around=around, stiffness=stiffness,
                    coupling=coupling, along=along, across=across, max_stiffness=max_stiffness, keys=keys, **parts)
