"""The lattice: nx x ny blocks on a square lattice (a fault plane), nx along strike and ny across it, each on the
loader's spring (stiffness 1) and joined to its four nearest neighbours by springs of stiffness l^2 along strike and
l_y^2 across it, free edges (a missing neighbour is the block itself, as at the chain's free ends).

Block i sits at x = i % nx along strike, y = i // nx across it. The force on it (c-free frame, as the chain's):

    F_i = F0 + nu tau - y_i + l^2 (y_right - 2 y_i + y_left) + l_y^2 (y_up - 2 y_i + y_down)

With ny = 1 every across-strike term is exactly +0.0 (a missing neighbour's slip is the block's own), so the lattice
of one row computes the chain's numbers bit for bit; its creep clusters are then runs, solved by the chain's own
tridiagonal algorithms (the same operations), and a plane's clusters by geometry/graph.py's banded elimination in
index order (the band as wide as the cluster is along strike).
"""
from collections import namedtuple

import numba as nb

from ..workspace import CR_DU, F0, UNTOUCHED, Y
from ..interpolant import slip_at
from . import chain, creeping, graph


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


@nb.njit(cache=True, inline="always")
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


# -- the creep phase's clusters: a plane's by the graph's banded elimination, one row's by the chain's own algorithms
# (the same operations: one row is the chain bit for bit)

@nb.njit(cache=True)
def _as_chain(g):
    return chain.ChainParams(g.l2)


@nb.njit(cache=True)
def stable(g, C, n, lst, m):
    if g.ny == 1:
        return chain.stable(_as_chain(g), C, n, lst, m)
    return graph.stable(g, C, n, lst, m)


@nb.njit(cache=True)
def fastest_creep(g, C, n, nu, lst, m):
    if g.ny == 1:
        chain.fastest_creep(_as_chain(g), C, n, nu, lst, m)
    else:
        graph.fastest_creep(g, C, n, nu, lst, m)


@nb.njit(cache=True, inline="always")
def _creep_slip(C, i, j):
    """A creep step's slip CR_DU of neighbour j of block i if it creeps (0 if it does not or is missing)."""
    return C[j, CR_DU] if j != i and creeping(C, j) else 0.0


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
        if k != j and creeping(C, k):
            slip_x += C[k, CR_DU]
    slip_y = 0.0
    for k in (down(g, j), up(g, j, n)):
        if k != j and creeping(C, k):
            slip_y += C[k, CR_DU]
    return g.l2 * x * slip_x + g.l2y * x * slip_y


@nb.njit(cache=True)
def creep_solve(g, C, lst, m, n):
    if g.ny == 1:
        return chain.creep_solve(_as_chain(g), C, lst, m, n)
    return graph.creep_solve(g, C, lst, m, n)


def _record(model):
    return LatticeParams(nx=int(model.N), ny=int(model.M), l2=float(model.l) ** 2, l2y=float(model.l_across) ** 2)


GEOMETRY = graph.geometry("lattice", LatticeParams, _record, neighbours=neighbours, around=around, stiffness=stiffness,
                          coupling=coupling, along=along, across=across, max_stiffness=max_stiffness,
                          spring_force=spring_force, spring_force_at=spring_force_at, drop_stiffness=drop_stiffness,
                          spring_energy=spring_energy, stable=stable, fastest_creep=fastest_creep,
                          creep_force=creep_force, creep_load=creep_load, creep_solve=creep_solve,
                          keys=("M", "l_across"), grid=True)
