"""Event histories: snapshots of an event's velocity and slip profiles as it runs, for the events a run asks for.

A run that records histories (output.history > 0) gives the workspace a buffer `history` of snapshot rows and
the control vector `hctl` (workspace.HC_*). While hctl[HC_ON] is 1, continue_event takes a snapshot at the end
of an accepted step (never a step of its own: the event's arithmetic is the same with and without histories)
when the event's local time has advanced by hctl[HC_DT] since the last snapshot, or its largest velocity has
changed by a factor hctl[HC_RATIO] either way, and always at its first step and at its end (the final slip
profile, whose sum is the event's slip). So the slow initial phase is sampled by velocity, decade by decade,
and the rupture by time. A row is [local time since the onset, lo, hi, blocks sliding, velocities (n), slips (n)],
valid on
the blocks lo..hi (the blocks the event has touched lie there; the others are at rest with no slip). When the
buffer is full the later snapshots are dropped and counted (HC_DROPPED), the end taking the last row (the
snapshot there counted as dropped instead).

chain.simulate ends its call after an inertial event whose slip reaches hctl[HC_SLIP_MIN] (HC_READY = 1): the
caller copies the buffer out (ensemble/run/trajectory.py). Ending a call early changes no event (any budget
gives the same events).
"""
import numba as nb

from .workspace import (HC_COUNT, HC_DROPPED, HC_DT, HC_ON, HC_RATIO, HC_TAU, HC_V, H_HI, H_LO, H_NA, H_TAU,
                        H_VALUES, V, Y)


@nb.njit(cache=True)
def begin(arrays):
    """A new event: no snapshot yet."""
    hc = arrays.hctl
    if arrays.history.shape[0] > 0:
        hc[HC_COUNT] = 0.0
        hc[HC_DROPPED] = 0.0
        hc[HC_TAU] = 0.0
        hc[HC_V] = 0.0


@nb.njit(cache=True, inline="always")
def recording_history(arrays):
    """Whether the event in progress takes snapshots (checked once per kernel call: a call per step would cost
    the events without histories their share, benchmarks/results/revisions_histories_*)."""
    return arrays.history.shape[0] > 0 and arrays.hctl[HC_ON] != 0.0


@nb.njit(cache=True)
def snapshot(arrays, n, na, nt, tau, final):
    """After an accepted step (final: the event has ended), a snapshot if one is due."""
    H, hc = arrays.history, arrays.hctl
    if H.shape[0] == 0 or hc[HC_ON] == 0.0:
        return
    W, act = arrays.W, arrays.act
    vmax = 0.0
    for k in range(na):
        vmax = max(vmax, W[act[k], V])
    count = int(hc[HC_COUNT])
    due = (final or count == 0 or tau - hc[HC_TAU] >= hc[HC_DT] or vmax > hc[HC_V] * hc[HC_RATIO]
           or vmax * hc[HC_RATIO] < hc[HC_V])
    if not due:
        return
    row = count
    if row >= H.shape[0]:
        hc[HC_DROPPED] += 1.0     # (as if taken: the rule goes on as without a limit)
        hc[HC_TAU] = tau
        hc[HC_V] = vmax
        if not final:
            return
        row = H.shape[0] - 1      # the end overwrites the last row (dropped instead): the end is always there
    lo, hi = n, -1
    touched = arrays.touched
    for k in range(nt):
        lo = min(lo, touched[k])
        hi = max(hi, touched[k])
    H[row, H_TAU] = tau
    H[row, H_LO] = lo
    H[row, H_HI] = hi
    H[row, H_NA] = na
    for i in range(lo, hi + 1):
        H[row, H_VALUES + i] = W[i, V]
        H[row, H_VALUES + n + i] = W[i, Y]
    hc[HC_COUNT] = row + 1
    hc[HC_TAU] = tau
    hc[HC_V] = vmax
