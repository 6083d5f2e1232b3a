"""Local recurrence times of large events.

For each event i with mu_i >= mu_c, T_i is the time to the next event j > i
(same trajectory) with mu_j >= mu_c and |epicenter_j - epicenter_i| <= window.
Events whose rupture reaches neither end of the chain (boundary false) are the
"interior" subset. The scan streams through a task in time order: large events
still waiting for their successor are "pending"; two pending events are always
more than `window` blocks apart (the later one would have closed the earlier),
so at most N / window + 1 of them exist whatever the catalog length.
"""
import numba as nb
import numpy as np

import ensemble.model  # noqa: F401  (first: numba caches scan in the package's cache, ensemble/kernel_cache.py)


@nb.njit(cache=True)
def scan(t, epicenter, mu, boundary, mu_c, window, offset, pending_t, pending_epi, pending_int,
         pending_src, n_pending, out_src, out_T, out_interior):
    """Close pending large events with the large events of this chunk.

    pending_*: arrays of capacity >= N / window + 2 holding the pending events
    (time, epicenter, interior flag, index in the task); n_pending their number.
    Event j of the chunk has index offset + j in the task. For every closed
    event writes its index, T and interior flag into out_* (capacity len(t) +
    capacity of pending). Returns (n_pending, n_out).
    """
    n_out = 0
    for j in range(t.shape[0]):
        if mu[j] < mu_c:
            continue
        k = 0
        while k < n_pending:
            if abs(epicenter[j] - pending_epi[k]) <= window:
                out_src[n_out] = pending_src[k]
                out_T[n_out] = t[j] - pending_t[k]
                out_interior[n_out] = pending_int[k]
                n_out += 1
                n_pending -= 1
                pending_t[k] = pending_t[n_pending]
                pending_epi[k] = pending_epi[n_pending]
                pending_int[k] = pending_int[n_pending]
                pending_src[k] = pending_src[n_pending]
            else:
                k += 1
        pending_t[n_pending] = t[j]
        pending_epi[n_pending] = epicenter[j]
        pending_int[n_pending] = not boundary[j]
        pending_src[n_pending] = offset + j
        n_pending += 1
    return n_pending, n_out


class RecurrenceScanner:
    """Streams one task's events (in time order, chunk by chunk) into recurrence times."""

    def __init__(self, n_blocks, mu_c, window):
        cap = n_blocks // max(window, 1) + 4
        self.mu_c, self.window = mu_c, window
        self.t = np.zeros(cap)
        self.epi = np.zeros(cap, dtype=np.int64)
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
        self.n, n_out = scan(t, epicenter.astype(np.int64), mu, boundary.astype(np.bool_), self.mu_c,
                             self.window, self.offset, self.t, self.epi, self.interior, self.src,
                             self.n, src, T, interior)
        self.offset += len(t)
        return src[:n_out], T[:n_out], interior[:n_out]
