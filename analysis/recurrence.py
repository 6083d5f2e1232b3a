"""Local recurrence times of large events.

For each event i with mu_i >= mu_c, T_i is the time to the next event j > i
(same trajectory) with mu_j >= mu_c whose epicenter lies within `window` blocks
of i's: d(epicenter_j, epicenter_i) <= window, the distance of the geometry
(analysis/geometry.py: Euclidean in block units, dx along strike and dy across;
on a chain |epicenter_j - epicenter_i|). It is compared squared, in integers,
dx^2 + dy^2 <= window^2, which on a chain (dy = 0) is |dx| <= window exactly.
Events whose rupture reaches no edge (boundary false: neither end of the chain,
no edge of a plane) are the "interior" subset. The scan streams through a task
in time order: large events still waiting for their successor are "pending";
two pending events are always more than `window` blocks apart (the later one
would have closed the earlier), so at most the geometry's packing bound of them
exist whatever the catalog length (Shape.pending: N / window + 4 on a chain);
the scan checks it as well and stops rather than write past its buffers.
"""
import numba as nb
import numpy as np

import ensemble.model  # noqa: F401  (first: numba caches scan in the package's cache, ensemble/kernel_cache.py)

from . import geometry


@nb.njit(cache=True)
def scan(t, epicenter, mu, boundary, mu_c, n_along, n_blocks, window, offset, pending_t, pending_x, pending_y,
         pending_int, pending_src, n_pending, out_src, out_T, out_interior):
    """Close pending large events with the large events of this chunk.

    epicenter: each event's block, at x = epicenter % n_along along strike and y = epicenter // n_along across
    (y 0 on a chain, n_along = N); n_blocks: the task's blocks; window: in blocks. On one row (a chain) the test
    is |dx| <= window, else dx^2 + dy^2 <= window^2 in integers (the same test where dy = 0; the row's own loop,
    which leaves pending_y alone, keeps a chain's scan as fast as before the plane: one loop choosing its test
    inside took 12 % longer at window 2 over 2e6 events of a chain).
    pending_*: arrays of capacity at least the geometry's packing bound (Shape.pending) holding the pending events
    (time, epicenter x and y, interior flag, index in the task); n_pending their number.
    Event j of the chunk has index offset + j in the task. For every closed
    event writes its index, T and interior flag into out_* (capacity len(t) +
    capacity of pending). Returns (n_pending, n_out); n_pending -1 where a large event found the pending
    buffers full (more pending events than the bound allows: nothing is written past them), -2 where a large
    event's epicenter lies outside the n_blocks blocks (the bound holds for those only).
    """
    n_out = 0
    capacity = pending_t.shape[0]
    one_row = n_blocks <= n_along
    window2 = window * window
    for j in range(t.shape[0]):
        if mu[j] < mu_c:
            continue
        if epicenter[j] < 0 or epicenter[j] >= n_blocks:
            return -2, n_out
        k = 0
        if one_row:
            xj, yj = epicenter[j], 0
            while k < n_pending:
                if abs(xj - pending_x[k]) <= window:
                    out_src[n_out] = pending_src[k]
                    out_T[n_out] = t[j] - pending_t[k]
                    out_interior[n_out] = pending_int[k]
                    n_out += 1
                    n_pending -= 1
                    pending_t[k] = pending_t[n_pending]
                    pending_x[k] = pending_x[n_pending]
                    pending_int[k] = pending_int[n_pending]
                    pending_src[k] = pending_src[n_pending]
                else:
                    k += 1
        else:
            xj, yj = epicenter[j] % n_along, epicenter[j] // n_along
            while k < n_pending:
                dx = xj - pending_x[k]
                dy = yj - pending_y[k]
                if dx * dx + dy * dy <= window2:
                    out_src[n_out] = pending_src[k]
                    out_T[n_out] = t[j] - pending_t[k]
                    out_interior[n_out] = pending_int[k]
                    n_out += 1
                    n_pending -= 1
                    pending_t[k] = pending_t[n_pending]
                    pending_x[k] = pending_x[n_pending]
                    pending_y[k] = pending_y[n_pending]
                    pending_int[k] = pending_int[n_pending]
                    pending_src[k] = pending_src[n_pending]
                else:
                    k += 1
        if n_pending == capacity:
            return -1, n_out
        pending_t[n_pending] = t[j]
        pending_x[n_pending] = xj
        pending_y[n_pending] = yj
        pending_int[n_pending] = not boundary[j]
        pending_src[n_pending] = offset + j
        n_pending += 1
    return n_pending, n_out


class RecurrenceScanner:
    """Streams one task's events (in time order, chunk by chunk) into recurrence times. blocks: the task's
    geometry.Shape, or its number of blocks (a chain)."""

    def __init__(self, blocks, mu_c, window):
        self.shape = geometry.shape(blocks)
        cap = self.shape.pending(window)
        self.mu_c, self.window = mu_c, window
        self.t = np.zeros(cap)
        self.x = np.zeros(cap, dtype=np.int64)
        self.y = np.zeros(cap, dtype=np.int64)
        self.interior = np.zeros(cap, dtype=np.bool_)
        self.src = np.zeros(cap, dtype=np.int64)
        self.n = 0
        self.offset = 0

    def feed(self, t, epicenter, mu, boundary):
        """Returns (index of the starting event within the task, T, interior) of events closed now."""
        size = len(t) + len(self.t)
        src = np.empty(size, dtype=np.int64)
        T = np.empty(size)
        interior = np.empty(size, dtype=np.bool_)
        self.n, n_out = scan(t, epicenter.astype(np.int64), mu, boundary.astype(np.bool_), self.mu_c, self.shape.N,
                             self.shape.n_blocks, int(self.window), self.offset, self.t, self.x, self.y, self.interior,
                             self.src, self.n, src, T, interior)
        if self.n == -2:   # (the catalog's reader checks the rows' ranges too: this is the scanner's own guard)
            raise ValueError(f"recurrence scan: an epicenter outside the {self.shape.n_blocks} blocks of the task")
        if self.n < 0:
            raise RuntimeError(f"recurrence scan: more than {len(self.t)} large events pending at once, more than "
                               f"the {self.shape.geometry}'s packing bound allows at window {self.window} "
                               "(analysis/geometry.py)")
        self.offset += len(t)
        return src[:n_out], T[:n_out], interior[:n_out]
