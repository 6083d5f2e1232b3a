"""Lazy quiet loading and the onset schedule between events (pure numba kernels).

Between events every block is at rest, so its force grows as F + nu * dt and its
state as theta + dt. Instead of loading all N blocks at every event, each block
keeps its (force W[i, F0], state W[i, P]) together with the time `since[i]` at
which they hold, and is brought forward ("materialized") only when an event
reads it: the blocks that slide and their neighbours. The onset time of every
block at rest is kept in a binary min-tree (`tree`), so the next epicenter is
found in O(1) and an event updates only the entries of the blocks it changed:
the cost of an event scales with the blocks it touches, not with N.

Times are absolute and held as unevaluated sums of two float64 (hi, lo): a run
reaches t ~ 1e15, where one float64 resolves only ~0.1, while the time a block
has been at rest must be known to far better than its state theta (which can be
~1e-3 just after it stopped). The difference of two such times is exact to
float64 rounding of the difference itself. The tree keys are single float64
(only used to order the blocks; the epicenter's onset is recomputed exactly).
"""
import math

import numba as nb
import numpy as np

from .laws import onset_delay, rest_state
from .workspace import F0, P


@nb.njit(cache=True)
def advance_clock(clock, dt):
    """clock[0] + clock[1] += dt without losing the low-order bits (two-sum)."""
    s = clock[0] + dt
    bp = s - clock[0]
    clock[1] += (clock[0] - (s - bp)) + (dt - bp)
    clock[0] = s


@nb.njit(cache=True, inline="always")
def elapsed(clock, since, i):
    """clock - since[i] for two-float times."""
    return (clock[0] - since[i, 0]) + (clock[1] - since[i, 1])


@nb.njit(cache=True)
def materialize(W, since, i, clock, p):
    """Bring block i (at rest since since[i]) forward to the time `clock` (p: params.KernelParams)."""
    dt = elapsed(clock, since, i)
    if dt > 0.0:
        W[i, F0] += p.nu * dt
        W[i, P] = rest_state(p.law, W[i, P], dt)
    since[i, 0] = clock[0]
    since[i, 1] = clock[1]


@nb.njit(cache=True)
def onset_key(W, since, i, p):
    """Approximate absolute onset time of block i by loading alone (orders the tree)."""
    return since[i, 0] + (since[i, 1] + onset_delay(p.law, W[i, F0], W[i, P], p.nu))


# The tree: tree[1] is the root, node k has children 2k, 2k+1, and block i is
# the leaf m + i with m = len(tree) // 2 a power of two >= N (workspace.tree_size);
# leaves past N hold inf. A node holds the smaller key of its children.


@nb.njit(cache=True)
def tree_set(tree, i, key):
    """Set block i's key and repair the minima on its path to the root: O(log N)."""
    k = tree.shape[0] // 2 + i
    tree[k] = key
    k //= 2
    while k >= 1:
        smaller = min(tree[2 * k], tree[2 * k + 1])
        if tree[k] == smaller:
            break
        tree[k] = smaller
        k //= 2


@nb.njit(cache=True)
def tree_min(tree):
    """(smallest key, its block): O(log N) descent along the minima.

    The block is always one of the chain's, whatever the keys: the descent goes right only
    to a strictly smaller key, so a NaN (which compares false) sends it left, and the left
    child of a node that holds a block holds one too (blocks are the leftmost leaves); a
    subtree of padding holds inf, never smaller. Ties go left.
    """
    k = 1
    m = tree.shape[0] // 2
    while k < m:
        k = 2 * k + 1 if tree[2 * k + 1] < tree[2 * k] else 2 * k
    return tree[1], k - m


@nb.njit(cache=True)
def build_schedule(W, since, tree, p):
    """Every block's onset key, and the minima: O(N), once per kernel call."""
    n = W.shape[0]
    m = tree.shape[0] // 2
    tree[m:] = np.inf
    for i in range(n):
        tree[m + i] = onset_key(W, since, i, p)
    for k in range(m - 1, 0, -1):
        tree[k] = min(tree[2 * k], tree[2 * k + 1])


@nb.njit(cache=True)
def finite_state(W, since):
    """Every block's force, state and time are finite (checked once per loaded state: a NaN
    would otherwise hide in the schedule, whose keys only order the blocks)."""
    for i in range(W.shape[0]):
        if not (math.isfinite(W[i, F0]) and math.isfinite(W[i, P]) and math.isfinite(since[i, 0])
                and math.isfinite(since[i, 1])):
            return False
    return True
