"""Geometries: the registry, and the calls through which the kernels use a geometry (docs/design/geometry.md).

A geometry is one module of this package that defines `GEOMETRY`, a `Geometry` record: how the blocks are joined
by springs. The kernels call the functions of this module, each taking the geometry's parameter record
(KernelParams.geom) first. That record is a namedtuple of the geometry's own class (chain.ChainParams, ...), so
numba compiles the kernels once per geometry, and each call resolves, at compile time, to the geometry's own
function (numba.extending.overload, inlined), as the friction laws' calls do (laws/__init__.py): no branch on
the geometry at run time, and a geometry's kernels are its own (the chain's arithmetic is not a special case of
another's: docs/design/geometry.md measures what that would cost).

The built-ins are the chain (geometry/chain.py) and the lattice (geometry/lattice.py, N x M blocks); every kernel
loop (the steps, the event's, the creep phase's) goes through here. A new geometry declares its neighbours and
springs and takes the rest from geometry/graph.py (forces, energy, clusters and their creep, and K x for the
Python side: ensemble/energy.py).

A geometry's blocks are numbered 0..n-1; a missing neighbour (a free edge) is the block itself, so loops over
`neighbours` skip j == i and a spring to a missing neighbour is never stretched (the ghost u_{-1} = u_0).
"""
import importlib
import pkgutil
from dataclasses import dataclass

import numba as nb
from numba.extending import overload

from ..workspace import CR_EP, SLIDING

# The smallest eigenvalue of a geometry's stiffness operator where every block is on the loader's spring 1: every
# block moving together stretches only the loader's springs. No cluster of creeping blocks is softer, so a law
# whose steady creep weakens by at most this never turns unstable (laws: steady_weakening).
SOFTEST_STIFFNESS = 1.0


@dataclass(frozen=True)
class Geometry:
    """What a geometry supplies. Its kernel functions are numba-compiled and take its record (`params`) first."""
    name: str             # the geometry's name
    params: type          # namedtuple class of the record the kernels read
    record: object        # model (config.Model) -> that record
    spring_force: object  # (g, W, col, i, n, F0, tau, nu) -> the force on block i at local time tau of an event,
                          # with the slips since its start in column col of W (n blocks), F0 the block's force at
                          # the start (c-free frame), nu the loader's velocity during the event
    spring_force_at: object   # (g, W, flag, x, i, n, F0, tau, nu) -> the same at fraction x of the event's step,
                              # the neighbours' slips on its interpolant (interpolant.slip_at), the block's W[i, Y]
    neighbours: object    # (g, i, n) -> tuple of block i's neighbours, in a fixed order (i where one is missing)
    around: object        # (g, i, n) -> tuple of block i and its neighbours (the blocks whose onset i's slip moves)
    stiffness: object     # (g, i, n) -> K_ii: the loader's spring 1 and the springs to i's neighbours
    coupling: object      # (g, i, j) -> the spring between neighbours i and j (-K_ij)
    along: object         # (g, i) -> block i's position along strike (an event's first and last block)
    across: object        # (g, i) -> its position across strike (0 on a chain)
    drop_stiffness: object    # (g, W, i, n) -> 1 and the springs from block i to neighbours that did not slip
                              # (W[j, Y] not > 0): the force an event's slip of i takes off i alone
    spring_energy: object     # (g, W, flag, i, n, stored, y) -> stored plus the energy of block i's springs,
                              # each spring counted once over an event's touched blocks (a spring to a touched
                              # neighbour counted at one of its two ends, flag UNTOUCHED the others)
    max_stiffness: object     # (g, n) -> the largest K_ii (the shortest inertial period)
    # the creep phase's clusters (creep.py): connected sets of blocks, their stiffness K_C the rows and columns of K
    cluster: object       # (g, C, flag, kind, n, j, out, seen) -> m: the connected blocks around j that are
                          # members of kind (member(), j counted) into out[:m] in increasing order, each marked
                          # seen[i] = 1
    stable: object        # (g, C, n, lst, m) -> K_C - diag(C[lst, CR_W]) is positive definite (lst[:m] a cluster)
    fastest_creep: object     # (g, C, n, nu, lst, m): C[lst, CR_RES] = (K_C - diag(max(CR_W, 0)))^-1 nu 1
    creep_force: object   # (g, C, W, i, n, nu, h) -> creeping block i's force after its step h (creep slips CR_DU)
    creep_load: object    # (g, C, j, n, x) -> the force on resting block j from x of its creeping neighbours' CR_DU
    creep_solve: object   # (g, C, lst, m, n) -> -1 or the block of the first non-negative pivot: the creep's Newton
                          # update of the creeping blocks lst[:m] into CR_UPPER (Jacobian diagonal CR_DIAG, residual
                          # CR_RES, J[i, j] = K_ij h_j; pivots into CR_DIAG)
    keys: tuple = ()      # the [model] keys of the geometry's shape it takes (of KEYS: "M", "l_across")
    grid: bool = False    # block i lies at (i % N, i // N) of an N x M grid with free edges and its distances are
                          # Euclidean there: the analysis reads its catalogs (analysis/geometry.py); a geometry
                          # whose distances differ (a ring's ends joined) leaves it False, and the analysis
                          # refuses its catalogs in one line

    def kernel_params(self, model):
        """The geometry's record for the kernels from a config's model section."""
        return self.record(model)


# [model] keys a geometry may take (Geometry.keys) and their values when it does not: config.py refuses another
KEYS = {"M": 1, "l_across": None}

# what a cluster is made of (Geometry.cluster): creeping blocks (creep arrays C), or sliding ones (an event's flag)
CREEPING = 0
SLIDING_NOW = 1


@nb.njit(cache=True, inline="always")
def creeping(C, i):
    """Block i creeps (the creep arrays C: it belongs to an episode)."""
    return C[i, CR_EP] != 0.0


@nb.njit(cache=True, inline="always")
def member(C, flag, kind, i):
    """Block i belongs to a cluster of this kind."""
    if kind == CREEPING:
        return creeping(C, i)
    return flag[i] == SLIDING


_BY_PARAMS = {}     # a geometry's record class -> the geometry (filled by the discovery below the calls)


def _dispatch(name, args):
    """The call `name` of the geometry of the record g (the first argument): a stub for the kernels, resolved
    at compile time by numba.extending.overload to the geometry's own function (inlined)."""
    src = (f"def {name}({args}):\n    pass\n"
           f"def _impl({args}):\n    fn = _BY_PARAMS[g.instance_class].{name}\n"
           f"    return lambda {args}: fn({args})\n")
    scope = {"_BY_PARAMS": _BY_PARAMS}
    exec(src, scope)
    stub = scope[name]
    stub.__doc__ = f"Geometry.{name}, resolved to the geometry of the record g."
    overload(stub, inline="always")(scope["_impl"])
    return stub


spring_force = _dispatch("spring_force", "g, W, col, i, n, F0, tau, nu")
spring_force_at = _dispatch("spring_force_at", "g, W, flag, x, i, n, F0, tau, nu")
neighbours = _dispatch("neighbours", "g, i, n")
around = _dispatch("around", "g, i, n")
stiffness = _dispatch("stiffness", "g, i, n")
coupling = _dispatch("coupling", "g, i, j")
along = _dispatch("along", "g, i")
across = _dispatch("across", "g, i")
drop_stiffness = _dispatch("drop_stiffness", "g, W, i, n")
spring_energy = _dispatch("spring_energy", "g, W, flag, i, n, stored, y")
max_stiffness = _dispatch("max_stiffness", "g, n")
cluster = _dispatch("cluster", "g, C, flag, kind, n, j, out, seen")
stable = _dispatch("stable", "g, C, n, lst, m")
fastest_creep = _dispatch("fastest_creep", "g, C, n, nu, lst, m")
creep_force = _dispatch("creep_force", "g, C, W, i, n, nu, h")
creep_load = _dispatch("creep_load", "g, C, j, n, x")
creep_solve = _dispatch("creep_solve", "g, C, lst, m, n")


def _discover():
    found = {}
    for info in pkgutil.iter_modules(__path__):
        geometry = getattr(importlib.import_module(f"{__name__}.{info.name}"), "GEOMETRY", None)
        if isinstance(geometry, Geometry):
            if geometry.name in found:
                raise RuntimeError(f"two geometries named {geometry.name!r}")
            found[geometry.name] = geometry
    return found


GEOMETRIES = _discover()        # name -> Geometry
DEFAULT = "chain"
_BY_PARAMS.update({geometry.params: geometry for geometry in GEOMETRIES.values()})


def get(name):
    return GEOMETRIES[name]
