"""A trajectory of the chain: quiet loading, jump to the next onset, integrate the event.

`simulate` runs a batch of events on the between-events state held in the
workspace arrays and writes one row per event into caller-allocated arrays.
Time is kept as a compensated sum (clock[0] + clock[1]) because a long run
reaches t ~ 1e15, where a single float64 resolves only ~0.1; everything the
physics uses is a time difference (time since the onset, since a block came to
rest), so accuracy does not decay as the run goes on. Between events only the
blocks an event touched are updated (schedule.py).
"""
import math

import numba as nb
import numpy as np

from .event import integrate_event
from .onset import onset_delay
from .schedule import advance_clock, build_schedule, materialize, tree_min
from .workspace import D_DURATION, D_SLIP, F0, NTRACE, OK, P


@nb.njit(cache=True)
def simulate(W, act, flag, touched, stuck, since, tree, diag, clock, l2, nu, a, b, method, dt, rtol,
             atol, h_max, max_duration, max_steps, n_events, out_t, out_epicenter, out_diag):
    """Run n_events events from the time `clock`; returns (status, number of events completed).

    Every block is at rest with its state at time since[i] (see schedule.py); `tree`
    holds their onset keys, or NaN at the root after a new state was loaded.
    out_t[k] is the onset time of event k, out_epicenter[k] its epicenter,
    out_diag[k] the event's diagnostics vector (workspace.D_*). On a status
    other than OK the state is that after the failed event, which is not counted.
    """
    n = W.shape[0]
    no_profile = np.empty(0)
    no_trace = np.empty((0, NTRACE))
    if math.isnan(tree[1]):      # a freshly loaded state (Workspace.load): schedule every block
        build_schedule(W, since, tree, nu, b)
    onset = np.empty(2)
    k = 0
    while k < n_events:
        _, epicenter = tree_min(tree)
        # The onset, exactly: the epicenter's own delay from its state (the tree
        # only orders the blocks), never before the end of the previous event.
        onset[0] = since[epicenter, 0]
        onset[1] = since[epicenter, 1]
        advance_clock(onset, onset_delay(W[epicenter, F0], W[epicenter, P], nu, b))
        if (onset[0] - clock[0]) + (onset[1] - clock[1]) > 0.0:
            clock[0] = onset[0]
            clock[1] = onset[1]
        materialize(W, since, epicenter, clock, nu)
        # Put the epicenter on its threshold, not a round-off below it, so the
        # event starts without a false stick (a force above it stays as it is).
        if W[epicenter, F0] < b * W[epicenter, P]:
            W[epicenter, F0] = b * W[epicenter, P]
        status = integrate_event(W, act, flag, touched, stuck, since, tree, clock, n, epicenter, 0.0,
                                 l2, nu, a, b, method, dt, rtol, atol, h_max, max_duration, max_steps,
                                 diag, no_profile, no_trace)
        if status != OK:
            return status, k
        t_onset = clock[0] + clock[1]
        advance_clock(clock, diag[D_DURATION])
        if diag[D_SLIP] == 0.0:
            continue    # nothing moved (an onset within round-off of the threshold): no event
        out_t[k] = t_onset
        out_epicenter[k] = epicenter
        out_diag[k, :] = diag
        k += 1
    return OK, n_events
