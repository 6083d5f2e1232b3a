"""Geometries: the registry, and the calls through which the kernels use a geometry (docs/design/geometry.md).

A geometry is one module of this package that defines `GEOMETRY`, a `Geometry` record: how the blocks are joined
by springs. The kernels call the functions of this module, each taking the geometry's parameter record
(KernelParams.geom) first. That record is a namedtuple of the geometry's own class (chain.ChainParams, ...), so
numba compiles the kernels once per geometry, and each call resolves, at compile time, to the geometry's own
function (numba.extending.overload, inlined), as the friction laws' calls do (laws/__init__.py): no branch on
the geometry at run time, and a geometry's kernels are its own (the chain's arithmetic is not a special case of
another's: docs/design/geometry.md measures what that would cost).

Today the chain is the one geometry, and the kernels' steps call it through here; the event's and the creep
phase's neighbour loops still import the chain's left and right from geometry/chain.py until they go through the
geometry too (docs/design/geometry.md, the order of work).
"""
import importlib
import pkgutil
from dataclasses import dataclass

from numba.extending import overload

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

    def kernel_params(self, model):
        """The geometry's record for the kernels from a config's model section."""
        return self.record(model)


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
_BY_PARAMS = {geometry.params: geometry for geometry in GEOMETRIES.values()}


def get(name):
    return GEOMETRIES[name]


def spring_force(g, W, col, i, n, F0, tau, nu):
    """The force on block i (Geometry.spring_force), resolved to the geometry of the record g."""


@overload(spring_force, inline="always")
def _spring_force(g, W, col, i, n, F0, tau, nu):
    fn = _BY_PARAMS[g.instance_class].spring_force
    return lambda g, W, col, i, n, F0, tau, nu: fn(g, W, col, i, n, F0, tau, nu)
