"""A trajectory of the chain: quiet loading, jump to the next onset, integrate the event.

`simulate` runs a batch of events on the between-events state held in the
workspace arrays and writes one row per event into caller-allocated arrays.
Time is kept as a compensated sum (clock[0] + clock[1]) because a long run
reaches t ~ 1e15, where a single float64 resolves only ~0.1; everything the
physics uses is a time difference (time since the onset, since a block came to
rest), so accuracy does not decay as the run goes on. Between events only the
blocks an event touched are updated (schedule.py).

A call is bounded by a work budget rather than by events alone, because one event can
cost minutes (a tiny RK4 step, a huge N) while the caller must serve signals, progress and
checkpoints every few tenths of a second. Work is counted in block-steps (event.py) plus
EVENT_WORK per event; a call may stop in the middle of an event and the next call continues
it, bit-identically (its state stays in the workspace: workspace.EV_*, undo.py).
"""
import math

import numba as nb
import numpy as np

from .creep import (ENDED, HANDOVER, after_event, continue_creep, join, loaded_past_threshold, off_schedule,
                    alone_creeps, possible, report)
from .event import begin_event, begin_handover, continue_event
from .laws import loader_moves, onset_delay, rest_state, threshold
from .schedule import advance_clock, build_schedule, finite_state, materialize, tree_min
from .undo import log_block
from .workspace import (BETWEEN, CS_ENDED, CS_NCREEP, D_DURATION, D_ENDING, D_KIND, D_SLIP, EV_CLOCK_HI,
                        EV_CLOCK_LO, EV_EPICENTER, EV_PHASE, F0, HC_ON, HC_READY, HC_SLIP_MIN, KIND_EVENT, NONFINITE,
                        NTRACE, OK, P, PAUSED)

# Work units charged for each event besides its block-steps: a fixed stand-in for the onset
# search (tree descent, onset delay), setting the event up and finishing it (O(log N) and
# O(blocks touched) operations), so that a budget also bounds a call of many one-block events.
EVENT_WORK = 32


@nb.njit(cache=True)
def simulate(arrays, clock, p, n_events, budget, out_t, out_epicenter, out_diag):
    """Run up to n_events events from the time `clock`, within `budget` work units, on the work
    arrays `arrays` (workspace.WorkArrays) with the parameters `p` (params.KernelParams).

    Returns (status, k), k the number of events completed in this call:
    OK and k = n_events, or OK and k < n_events when the budget ran out between two events or an event's
    history is ready (history.py: arrays.hctl[HC_READY] = 1, the event is row k - 1);
    PAUSED when it ran out in the middle of an event, which stays in the workspace (`event`,
    `undo`, and `clock` at its onset) and the next call continues (its row is then that
    call's first). Work: the block-steps of the events (event.py) plus EVENT_WORK per event
    begun. The budget is checked before each step and before each event, so a call overruns
    it by at most one step (its rejected tries and a redo after a cut included), or by
    EVENT_WORK; with budget >= 1 every call makes progress. Any budget gives
    the same events, bit for bit, as one call with workspace.UNLIMITED.

    Every block is at rest with its state at time since[i] (see schedule.py); `tree`
    holds their onset keys, or NaN at the root after a new state was loaded.
    out_t[k] is the onset time of event k, out_epicenter[k] its epicenter,
    out_diag[k] the event's diagnostics vector (workspace.D_*). On a status
    other than OK and PAUSED the state is that after the failed event, which is not counted;
    NONFINITE also stands for a NaN or inf among the parameters (p.max_step and p.max_duration
    may be inf: no bound) or the loaded state.
    """
    W, since, tree, diag, event, undo = arrays.W, arrays.since, arrays.tree, arrays.diag, arrays.event, arrays.undo
    n = W.shape[0]
    no_profile = np.empty(0)
    no_trace = np.empty((0, NTRACE))
    if not _finite_parameters(p):
        return NONFINITE, 0
    if math.isnan(tree[1]):      # a freshly loaded state (Workspace.load): schedule every block
        if not finite_state(W, since):
            return NONFINITE, 0
        build_schedule(W, since, tree, p)
        if possible(p, n):
            off_schedule(arrays, n, p)
    onset = np.empty(2)
    k = 0
    spent = 0
    creep_on = possible(p, n)
    cstate = arrays.cstate
    while k < n_events:
        handover = -1
        if event[EV_PHASE] == BETWEEN and creep_on and (cstate[CS_NCREEP] > 0.0 or cstate[CS_ENDED] > 0.0):
            # -- the creep phase (creep.py): its ended episodes are rows, then it runs up to the
            # next onset by loading, or hands over to an event
            if cstate[CS_ENDED] > 0.0:
                k += report(arrays, n, out_t, out_epicenter, out_diag, k)
                continue
            if spent >= budget:
                return OK, k
            code, used, handover = continue_creep(arrays, clock, n, p, budget - spent)
            spent += used
            if code == PAUSED:
                return OK, k
            if code == ENDED:
                continue
            if code != HANDOVER:
                handover = -1
        if event[EV_PHASE] == BETWEEN and handover >= 0:
            event[EV_CLOCK_HI] = clock[0]
            event[EV_CLOCK_LO] = clock[1]
            begin_handover(arrays, clock, n, handover, p)
            spent += EVENT_WORK
        elif event[EV_PHASE] == BETWEEN:
            if spent >= budget:
                return OK, k
            _, epicenter = tree_min(tree)
            # The onset, exactly: the epicenter's own delay from its state (the tree
            # only orders the blocks), never before the end of the previous event.
            delay = onset_delay(p.law, W[epicenter, F0], W[epicenter, P], p.nu)
            if not math.isfinite(delay):     # a NaN state, or inf: no block ever starts (b / nu > 1e308)
                return NONFINITE, k
            onset[0] = since[epicenter, 0]
            onset[1] = since[epicenter, 1]
            advance_clock(onset, delay)
            # a block stiffer than its law's weakening creeps instead of rupturing
            creeps_here = (creep_on and alone_creeps(arrays, n, p, epicenter)
                           and loaded_past_threshold(p, n, rest_state(p.law, W[epicenter, P], delay)))
            if not creeps_here:
                # from here on the event changes the between-events state: keep what it was
                event[EV_CLOCK_HI] = clock[0]
                event[EV_CLOCK_LO] = clock[1]
                log_block(W, since, event, undo, epicenter)
            if (onset[0] - clock[0]) + (onset[1] - clock[1]) > 0.0:
                clock[0] = onset[0]
                clock[1] = onset[1]
            materialize(W, since, epicenter, clock, p)
            # Put the epicenter on its threshold, not a round-off below it, so the event starts
            # without a false stick and creep from the threshold (a force above it stays as it is).
            if W[epicenter, F0] < threshold(p.law, W[epicenter, P]):
                W[epicenter, F0] = threshold(p.law, W[epicenter, P])
            if creeps_here:
                join(arrays, n, p, epicenter, 0.0, clock)
                continue
            begin_event(arrays, clock, n, epicenter, 0.0, p)
            spent += EVENT_WORK
        status, used = continue_event(arrays, clock, n, p, no_profile, no_trace, budget - spent)
        spent += used
        if status == PAUSED:
            return PAUSED, k
        t_onset = clock[0] + clock[1]
        if creep_on:
            onset[0], onset[1] = clock[0], clock[1]     # where the event took any creeping blocks
        if loader_moves(p.law):     # else the event took no loading time (laws/__init__.py)
            advance_clock(clock, diag[D_DURATION])
        if status != OK:
            return status, k
        if creep_on:
            after_event(arrays, n, p, onset, clock)
        if diag[D_SLIP] == 0.0:
            continue    # nothing moved (an onset within round-off of the threshold): no event
        out_t[k] = t_onset
        out_epicenter[k] = int(event[EV_EPICENTER])
        out_diag[k, :] = diag
        out_diag[k, D_KIND] = KIND_EVENT
        out_diag[k, D_ENDING] = 0.0
        k += 1
        hctl = arrays.hctl
        if hctl[HC_ON] != 0.0 and diag[D_SLIP] >= hctl[HC_SLIP_MIN]:
            hctl[HC_READY] = 1.0     # its snapshots are in `history`: the caller copies them (history.py)
            return OK, k
    return (OK if event[EV_PHASE] == BETWEEN else PAUSED), k


@nb.njit(cache=True)
def _finite_parameters(p):
    """No NaN or inf among the model and integrator parameters, but for the two bounds: the
    largest step and the longest event may be inf (no bound), though not NaN (which would
    silently disable them as well)."""
    return (math.isfinite(p.l2) and math.isfinite(p.nu) and _finite_law(p.law)
            and math.isfinite(p.dt) and math.isfinite(p.rtol) and math.isfinite(p.atol)
            and not math.isnan(p.max_step) and not math.isnan(p.max_duration))


@nb.njit(cache=True)
def _finite_law(law):
    """Every parameter of the friction law is finite (they are all floats)."""
    for x in law:
        if not math.isfinite(x):
            return False
    return True
