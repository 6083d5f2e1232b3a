"""Where inside a step a block sticks or starts: the earliest transition, located on the step's interpolant.

A step of the event (event.py) in which a sliding block's velocity reaches 0 (STICK), a resting
neighbour of a sliding block reaches its static threshold (ONSET_NEIGHBOUR), or a block nobody
watches does so by loading alone (ONSET_LOADING, at the schedule's t_far) is cut at the earliest of
these and redone up to it. Sticks and onsets are located alike, by one bisection (`locate`), on the
step's cubic Hermite interpolant: of the velocity for a stick, of the slips (and so of the force)
for an onset.
"""
import numba as nb

from .geometry import spring_force, spring_force_at
from .interpolant import hermite
from .laws import friction, loader_moves, rest_state, threshold
from .workspace import F0, K1V, P, SLIDING, TR, V, V0, Y

# the transition that ends a step early
NO_CUT = 0            # none inside the step
STICK = 1             # a sliding block's velocity reaches 0
ONSET_NEIGHBOUR = 2   # a resting neighbour of a sliding block reaches its threshold
ONSET_LOADING = 3     # a block nobody watches reaches its threshold by loading alone (t_far)

_BISECT = 60          # halvings: a transition is located to 2^-60 of the step


@nb.njit(cache=True, inline="always")
def event_nu(p):
    """The loader's velocity during an event: nu, or 0 for a law whose loader stands still then."""
    return p.nu if loader_moves(p.law) else 0.0


@nb.njit(cache=True, inline="always")
def rest_psi(W, j, tau, p):
    """psi of a block at rest since local time TR (its state grown since)."""
    return rest_state(p.law, W[j, P], tau - W[j, TR])


@nb.njit(cache=True, inline="always")
def force_now(W, n, j, tau, p):
    """Force on block j at local time tau, with the slips of the blocks as they are now."""
    return spring_force(p.geom, W, Y, j, n, W[j, F0], tau, event_nu(p))


@nb.njit(cache=True, inline="always")
def _excess_now(W, n, j, tau, p):
    """Force above the static threshold of resting block j at the current time."""
    return force_now(W, n, j, tau, p) - threshold(p.law, rest_psi(W, j, tau, p))


@nb.njit(cache=True, inline="always")
def above_threshold(W, flag, n, j, tau, p):
    """Block j is at rest and its force exceeds the static threshold at local time tau."""
    # Cheap filter first: the threshold of a resting block never falls (laws/__init__.py), so a
    # force below its threshold when it came to rest cannot start it.
    return (flag[j] != SLIDING and force_now(W, n, j, tau, p) > threshold(p.law, W[j, P])
            and _excess_now(W, n, j, tau, p) > 0.0)


@nb.njit(cache=True)
def pressed(W, n, i, tau, p):
    """Sliding block i has not moved in this step but is still at or above its threshold.

    A block that starts exactly on its threshold gains force above it slowly (for the aging
    law at the rate nu - b / theta, > 0 at an onset), which for small nu can stay below the
    rounding of the force for a step: it has not stopped, it has not started yet.
    """
    return (W[i, V0] == 0.0 and W[i, V] == 0.0
            and force_now(W, n, i, tau, p) - threshold(p.law, W[i, P]) >= 0.0)


@nb.njit(cache=True, inline="always")
def loading_cut(x_cut, who, kind, t_far, far, tau, h):
    """(x, block, kind): the earliest transition found so far inside the step of size h from local
    time tau, or the onset by loading alone at t_far of block `far` if it is earlier."""
    if t_far <= tau + h:
        x = max(t_far - tau, 0.0) / h
        if x < x_cut:
            return x, far, ONSET_LOADING
    return x_cut, who, kind


@nb.njit(cache=True, inline="always")
def velocity_slopes(W, n, i, tau, h, p):
    """Slopes, per unit fraction of the step, of sliding block i's velocity at the step's ends."""
    a_end = spring_force(p.geom, W, Y, i, n, W[i, F0], tau + h, event_nu(p)) - friction(p.law, W[i, V], W[i, P])
    return h * W[i, K1V], h * a_end


@nb.njit(cache=True, inline="always")
def locate(kind, W, flag, n, j, tau, h, v0, v1, d0, d1, p):
    """The earliest fraction x of the step by which transition `kind` of block j has happened (it
    has by the step's end), by bisection to 2^-60 on the step's Hermite interpolant: for a STICK,
    of the velocity (v0, v1 at the step's ends, slopes d0, d1) down to 0, for an onset of the
    force above the threshold (0 if it is at the step start already)."""
    if kind != STICK and _excess(W, flag, n, j, tau, h, 0.0, p) >= 0.0:
        return 0.0
    lo = 0.0
    hi = 1.0
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        if kind == STICK:
            happened = not (hermite(mid, v0, v1, d0, d1) > 0.0)
        else:
            happened = _excess(W, flag, n, j, tau, h, mid, p) > 0.0
        if happened:
            hi = mid
        else:
            lo = mid
    return hi


# Not inlined by numba: inside `locate`'s bisection loop numba's inlining puts spring_force_at's variables out of
# scope (a NumbaIRAssumptionWarning, an error in `python -m ensemble compile`); the reference counts of a call
# cost a plane's events about 8 %.
@nb.njit(cache=True)
def _excess(W, flag, n, j, tau, h, x, p):
    """Force above the static threshold of resting block j at fraction x of the step."""
    s = tau + x * h
    force = spring_force_at(p.geom, W, flag, x, j, n, W[j, F0], s, event_nu(p))
    return force - threshold(p.law, rest_psi(W, j, s, p))
