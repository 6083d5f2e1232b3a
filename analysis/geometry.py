"""Where a catalog's blocks lie and how far apart they are: the geometries the analysis reads, those of the
kernels' registry (ensemble/model/geometry/) that declare `grid` (merge.read refuses a catalog of any other in one
line).

Block i lies at x = i % N along strike and y = i // N across (ensemble/store/schema.py, /events/epicenter): the
chain is a plane of one row, y = 0. The distance between two blocks is Euclidean in block units,
sqrt(dx^2 + dy^2), which on one row is |i - j| exactly. The recurrences' window compares dx^2 + dy^2 with
window^2 in integers on a plane and |dx| with window on one row; the seismicity keeps the row's own kernels: a
chain's numbers are those of before, bit for bit.

A geometry's points are told apart by the task columns of its [model] keys beyond reduce.PARAMS (Geometry.keys
of the kernels' registry: two planes of other M or l_across never pool); the most large events that can be
pending at once in the recurrence scan, each more than `window` blocks from every other, is the packing bound
of one row or of a plane (Shape.pending: the scanner's buffers, analysis/recurrence.py).
"""
import math
import zlib
from dataclasses import dataclass

import numpy as np

from ensemble.model import geometry as kernel_geometry

CHAIN = "chain"


def _row_pending(N, window):
    """Blocks 0..N-1 pairwise more than `window` apart: gaps of window + 1 at least, so at most
    (N - 1) // (window + 1) + 1, and N for window 0; the bound N // window + 4 holds both."""
    return N // max(window, 1) + 4


def _plane_pending(N, M, window):
    """Blocks of the N x M plane pairwise more than `window` apart: cut the plane into squares of side x side
    blocks with (side - 1) sqrt(2) <= window (side - 1 = isqrt(window^2 // 2): the largest k with 2 k^2 <= window^2);
    two blocks of one square are at most (side - 1) sqrt(2) <= window apart, so each square holds at most one."""
    side = math.isqrt(window * window // 2) + 1
    return -(-N // side) * -(-M // side)


# name -> the kernels' Geometry, of those on the grid
GEOMETRIES = {name: g for name, g in kernel_geometry.GEOMETRIES.items() if g.grid}


@dataclass(frozen=True)
class Shape:
    """A task's blocks: its geometry's name, N along strike and M across (1 on a chain)."""
    geometry: str
    N: int
    M: int = 1

    @property
    def n_blocks(self):
        """The number of blocks, N M: what bins and fit ranges of block counts (n_slipped) reach."""
        return self.N * self.M

    def position(self, block):
        """(x along strike, y across) of the blocks (int64 arrays)."""
        block = np.asarray(block, dtype=np.int64)
        return block % self.N, block // self.N

    @property
    def one_row(self):
        """Its blocks lie on one row (a chain, or a plane of M = 1): the analysis' row kernels."""
        return self.M == 1

    def pending(self, window):
        window = int(window)
        return _row_pending(self.N, window) if self.one_row else _plane_pending(self.N, self.M, window)


def shape(blocks):
    """A Shape, or a number of blocks: a chain of that many (as the engine's callers gave it before the plane)."""
    return blocks if isinstance(blocks, Shape) else Shape(CHAIN, int(blocks))


def task_shape(tasks, k):
    """The Shape of row k of a task table (one without the geometry's columns: a chain)."""
    name = str(tasks["geometry"][k]) if "geometry" in tasks else CHAIN
    return Shape(name, int(tasks["N"][k]), int(tasks["M"][k]) if "M" in tasks else 1)


def point_key(tasks, g):
    """What tells the geometry of row g's point apart, beyond reduce.PARAMS: () on a chain (its points as before),
    else (name, the bits of each of its keys)."""
    name = str(tasks["geometry"][g]) if "geometry" in tasks else CHAIN
    keys = GEOMETRIES[name].keys
    if not keys:
        return ()
    return (name, *(np.float64(tasks[k][g]).view(np.uint64).item() for k in keys))


def point_params(tasks, g):
    """The geometry's parameters of row g's point ({} on a chain): geometry, and its keys."""
    name = str(tasks["geometry"][g]) if "geometry" in tasks else CHAIN
    keys = GEOMETRIES[name].keys
    return {"geometry": name, **{k: tasks[k][g].item() for k in keys}} if keys else {}


def spawn_key(params):
    """The bootstrap's spawn key entries of a point's geometry (merge.bootstrap_rng): none on a chain (its streams
    as before), else CRC-32 of its name and the bits of each of its keys."""
    name = params.get("geometry", CHAIN)
    keys = GEOMETRIES[name].keys
    if not keys:
        return []
    return [zlib.crc32(name.encode()), *(int(np.float64(params[k]).view(np.uint64)) for k in keys)]
