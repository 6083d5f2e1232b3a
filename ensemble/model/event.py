"""One event of the chain, integrated on the active set by the chosen method (methods.py).

Only sliding blocks are integrated. Blocks at rest that neighbour a sliding
block are checked for onset after every step; all other blocks at rest can only
start by loading, and the earliest such onset `t_far` comes from the onset tree
(schedule.py), looked at again only when a block starts or stops.

A step in which a block sticks (v reaches 0) or starts (its force reaches the
static threshold) is cut at that instant, located on the cubic Hermite
interpolant of the step, and redone with the shorter step. Clamping v to zero at
the end of a step instead would make the slip only second-order accurate.

One step of the event loop (continue_event) goes through its phases, each marked `# --` there:
the step-size control (control.py), the earliest transition inside the step (transitions.py, each
located by one bisection), the health check, the transitions at the step's end, and the
rescheduling of the blocks nobody watches any more (`_reschedule`). The phases that loop over the
sliding blocks every step stay in the loop's body: numba counts a reference (an atomic add and
subtract) for every array an inlined function receives, at every call, and as functions those
phases made an ark4 run measurably slower (a WorkArrays record counts once per array in it). The
helpers they call take scalars, or run only at a transition.

Work arrays (one record, `workspace.WorkArrays`): columns of the float array `W` hold per-block
quantities, `act` the active list, `flag` the blocks' states (workspace: UNTOUCHED, SLIDING,
STOPPED), `touched` the blocks that slid.

An event is begun (`begin_event`) and then integrated by `continue_event`, which returns
after a given amount of work if the event has not finished by then, its loop variables kept
in the event-state vector (one record, workspace.PausedEvent, each field in its slot EV_*,
saved and restored by name), and carries on from there at the next call:
every floating-point operation is the same as in one call, so the result is bit-identical.
Work is counted in block-steps: the sliding blocks of every step tried (rejected steps and
steps redone after a cut included), the quantity the cost of an event is proportional to.
"""
import math

import numba as nb
import numpy as np

from .control import accepted, next_step_size, record, retry_size
from .creep import cluster_of, possible, slow_enough
from .geometry import across, along, around, drop_stiffness, neighbours, spring_energy, stiffness, coupling
from .laws import loader_moves, onset_delay, rest_state, rk4_unstable, stiff_limit
from .methods import adaptive, take_step
from .schedule import advance_clock, materialize, onset_key, tree_min, tree_set
from .steppers import FIRST_KEPT, FIRST_LAST, FIRST_NEW
from .transitions import (NO_CUT, ONSET_LOADING, ONSET_NEIGHBOUR, STICK, above_threshold, event_nu, force_now,
                          loading_cut, locate, pressed, rest_psi, velocity_slopes)
from .history import begin as begin_history, recording_history, snapshot
from .undo import clear_log, log_block
from .workspace import (BETWEEN, D_ACROSS_FIRST, D_ACROSS_LAST,
                        D_BLOCK_STEPS, D_CUTS, D_DURATION, D_ELASTIC, D_ENERGY_SCALE, D_FIRST, D_LAST,
                        D_LOAD_WORK, D_NSLIP, D_REJECTED, D_RESIDUAL, D_SLIP, D_STEPS, D_STRESS_DROP, D_VMAX, D_WORK,
                        D_N_ONSET, D_T_SPREAD, D_T_WIDEST, D_N_WIDEST, EV_N_ONSET, EV_T_SPREAD, EV_T_WIDEST,
                        EV_N_WIDEST, EV_BLOCK_STEPS, EV_CUTS, EV_EPICENTER, EV_ERR_PREV, EV_FAR, EV_H_NEXT, EV_NA,
                        EV_NT, EV_PHASE, EV_REJECTED, EV_SLIP_TIME, EV_STEPS, EV_STILL, EV_T_FAR, EV_TAU, EV_TRACED,
                        EV_VMAX, EV_WORK, EV_YREST, F0, HD0, CR_HB, CR_V, CR_VN, HD1, IN_EVENT, NONFINITE, OK, P, P0,
                        PAUSED, SLIDING, STALLED, STOPPED, TOO_LONG, TR, TS, UNLIMITED, UNSTABLE, UNTOUCHED, V, V0, Y,
                        Y0, YS, PausedEvent)

# Steps in a row that leave the event's time where it was (a transition located at the step's start, cut to a step
# of no length, again and again) before the event ends with STALLED: a guard, not a regime. It was met once, with
# exp4 at N = 5, a = 100, b = 18, where 4e7 such steps went by in 4 minutes (two blocks taking turns: see `started`
# in continue_event, which ended that). Counted over paused calls too (EV_STILL), so it does not depend on the
# budget; a legitimate cut at the step's start happens a few times at most, then the step goes on.
# workspace.STATUS_TEXT[STALLED] gives the number.
STALL_STEPS = 10_000

# Stability limit of classical RK4 on the negative real axis: the state equation
# relaxes at rate 1/theta (= v in steady sliding), so dt / theta must stay below it.
RK4_STABILITY = 2.785


@nb.njit(cache=True)
def _adjacent_to_active(flag, n, j, p):
    for k in neighbours(p.geom, j, n):
        if flag[k] == SLIDING:
            return True
    return False


@nb.njit(cache=True)
def _loading_onset(W, flag, n, j, tau, p):
    """Local time at which resting block j starts by loading alone (inf if it is watched, or if
    the loader stands still during events)."""
    if not loader_moves(p.law) or flag[j] == SLIDING or _adjacent_to_active(flag, n, j, p):
        return np.inf
    return tau + onset_delay(p.law, force_now(W, n, j, tau, p), rest_psi(W, j, tau, p), p.nu)


@nb.njit(cache=True)
def _far_onset(W, flag, n, since, tree, t0, tau, p):
    """(local time, block) of the earliest onset by loading alone of a block nobody watches.

    The tree orders the candidates; the winner's onset is recomputed exactly:
    from its current force and state if the event has touched it (its state
    then holds at t0), else from its stored state without changing it.
    """
    if not loader_moves(p.law):
        return np.inf, -1
    key, j = tree_min(tree)
    if key == np.inf:
        return np.inf, -1
    if since[j, 0] == t0[0] and since[j, 1] == t0[1]:
        return _loading_onset(W, flag, n, j, tau, p), j
    t = (since[j, 0] - t0[0]) + (since[j, 1] - t0[1]) + onset_delay(p.law, W[j, F0], W[j, P], p.nu)
    return max(t, tau), j


@nb.njit(cache=True)
def _watch(W, since, tree, event, undo, t0, p, j):
    """Block j starts or neighbours a sliding block: bring it to t0, take it off the schedule."""
    log_block(W, since, event, undo, j)
    materialize(W, since, j, t0, p)
    tree_set(tree, j, np.inf)


@nb.njit(cache=True)
def _start(arrays, na, nt, t0, p, j, tau, yrest):
    """Block j starts to slide at local time tau; returns (na, nt, yrest)."""
    W, flag = arrays.W, arrays.flag
    for k in around(p.geom, j, W.shape[0]):
        _watch(W, arrays.since, arrays.tree, arrays.event, arrays.undo, t0, p, k)
    if flag[j] == STOPPED:
        yrest -= W[j, Y]
    else:
        arrays.touched[nt] = j
        nt += 1
    W[j, P] = rest_psi(W, j, tau, p)
    W[j, V] = 0.0
    W[j, TS] = tau
    flag[j] = SLIDING
    arrays.act[na] = j
    return na + 1, nt, yrest


@nb.njit(cache=True)
def integrate_event(arrays, t0, n, epicenter, v_start, p, profile, trace):
    """Integrate one event from the onset of `epicenter` at time t0 until every block is at rest.

    On entry (work arrays `arrays`, workspace.WorkArrays) every block is at rest, block i with
    force W[i, F0] and state psi W[i, P] at time since[i] (c-free frame; see schedule.py), `tree`
    holds every block's onset key, the epicenter is on its threshold at t0 (two-float time), the
    other columns and `flag` are zero, `event` is BETWEEN with an empty undo log. `v_start` is the epicenter's initial
    velocity (0 for a natural onset). `p` holds the parameters (params.KernelParams):
    the method p.method (methods.py) steps by p.dt if it is RK4; an adaptive one starts with p.dt
    and controls the step (at most p.max_step) so that the embedded error estimate stays below
    p.rtol, p.atol. On return the
    blocks the event touched hold the state at its end (the schedule updated), the other columns
    and `flag` are zero, and `diag` holds the event summary (see workspace.D_*). If `profile`
    has n entries it receives the slip of every block (else pass an empty
    array). If `trace` has rows, each step tried fills one (workspace.TRACE_COLUMNS, until the
    rows run out; a step cut at a located transition appears once, as tried). Returns a status code.

    This is begin_event and continue_event without a budget, in one call.
    """
    begin_event(arrays, t0, n, epicenter, v_start, p)
    status, _ = continue_event(arrays, t0, n, p, profile, trace, UNLIMITED)
    return status


@nb.njit(cache=True)
def begin_event(arrays, t0, n, epicenter, v_start, p):
    """Start an event at the onset of `epicenter` at time t0 (as integrate_event's entry).

    The epicenter and its neighbours are watched (their between-events values logged in `undo`),
    and the event's loop variables go into `event` (EV_*, EV_PHASE = IN_EVENT) for
    continue_event. EV_NUNDO and the clock entries are the caller's (chain.simulate).
    """
    W, event = arrays.W, arrays.event
    na, nt, yrest = _start(arrays, 0, 0, t0, p, epicenter, 0.0, 0.0)
    t_far, far = _far_onset(W, arrays.flag, n, arrays.since, arrays.tree, t0, 0.0, p)
    W[epicenter, V] = v_start
    event[EV_PHASE] = IN_EVENT
    event[EV_EPICENTER] = epicenter
    _nucleation_begins(event, nt)
    begin_history(arrays)
    snapshot(arrays, n, na, nt, 0.0, False)
    _keep(event, _at_onset(na=na, nt=nt, yrest=yrest, t_far=t_far, far=far, vmax=v_start, h_next=p.dt))


@nb.njit(cache=True)
def begin_handover(arrays, t0, n, epicenter, p):
    """Start an event where creep hands over to inertia (creep.continue_creep): `epicenter` starts
    at time t0 from its creep velocity (from rest if it was joining), and every block creeping in its run slides
    from its creep velocity (as begin_event otherwise; the creep arrays keep them until the event's end,
    creep.after_event)."""
    W, event, C = arrays.W, arrays.event, arrays.creep
    na, nt, yrest = _start(arrays, 0, 0, t0, p, epicenter, 0.0, 0.0)
    vmax = 0.0
    if C[epicenter, CR_V] > 0.0:
        W[epicenter, V] = C[epicenter, CR_V]
        vmax = W[epicenter, V]
    for k in range(cluster_of(C, arrays.flag, arrays.cluster, arrays.seen, n, p, epicenter)):
        i = arrays.cluster[k]
        if i != epicenter and C[i, CR_V] > 0.0:
            na, nt, yrest = _start(arrays, na, nt, t0, p, i, 0.0, yrest)
            W[i, V] = C[i, CR_V]
            vmax = max(vmax, W[i, V])
    t_far, far = _far_onset(W, arrays.flag, n, arrays.since, arrays.tree, t0, 0.0, p)
    event[EV_PHASE] = IN_EVENT
    event[EV_EPICENTER] = epicenter
    _nucleation_begins(event, nt)
    begin_history(arrays)
    snapshot(arrays, n, na, nt, 0.0, False)
    _keep(event, _at_onset(na=na, nt=nt, yrest=yrest, t_far=t_far, far=far, vmax=vmax, h_next=p.dt))


@nb.njit(cache=True, inline="always")
def _nucleation_begins(event, nt):
    """The event's nucleation markers at its onset, nt blocks sliding (workspace: D_N_ONSET ...)."""
    event[EV_N_ONSET] = nt
    event[EV_T_SPREAD] = -1.0
    event[EV_T_WIDEST] = 0.0
    event[EV_N_WIDEST] = nt


@nb.njit(cache=True, inline="always")
def _nucleation_step(event, na, nt, tau):
    """After an accepted step ending at local time tau: the sliding zone's first growth beyond the onset's
    blocks, and the widest the zone of sliding blocks (na of them) has been, first reached when."""
    if event[EV_T_SPREAD] < 0.0 and nt > event[EV_N_ONSET]:
        event[EV_T_SPREAD] = tau
    if na > event[EV_N_WIDEST]:
        event[EV_N_WIDEST] = na
        event[EV_T_WIDEST] = tau


@nb.njit(cache=True, inline="always")
def _at_onset(na, nt, yrest, t_far, far, vmax, h_next):
    """The loop variables (PausedEvent) of an event at its onset: the blocks started, nothing integrated yet."""
    return PausedEvent(na=na, nt=nt, yrest=yrest, t_far=t_far, far=far, tau=0.0, work=0.0, slip_time=0.0, steps=0,
                       block_steps=0, rejected=0, cuts=0, vmax=vmax, h_next=h_next, err_prev=1.0, traced=0,
                       still=0)


@nb.njit(cache=True, inline="always")
def _keep(event, s):
    """The loop variables of the event in progress (a PausedEvent) into the event-state vector, each
    field into its slot (workspace: field x in EV_X)."""
    event[EV_NA] = s.na
    event[EV_NT] = s.nt
    event[EV_YREST] = s.yrest
    event[EV_T_FAR] = s.t_far
    event[EV_FAR] = s.far
    event[EV_TAU] = s.tau
    event[EV_WORK] = s.work
    event[EV_SLIP_TIME] = s.slip_time
    event[EV_STEPS] = s.steps
    event[EV_BLOCK_STEPS] = s.block_steps
    event[EV_REJECTED] = s.rejected
    event[EV_CUTS] = s.cuts
    event[EV_VMAX] = s.vmax
    event[EV_H_NEXT] = s.h_next
    event[EV_ERR_PREV] = s.err_prev
    event[EV_TRACED] = s.traced
    event[EV_STILL] = s.still


@nb.njit(cache=True, inline="always")
def _resume(event):
    """The loop variables of the event in progress (a PausedEvent) from the event-state vector, each
    field from its slot; counts and block indices back to integers."""
    return PausedEvent(na=int(event[EV_NA]), nt=int(event[EV_NT]), yrest=event[EV_YREST], t_far=event[EV_T_FAR],
                       far=int(event[EV_FAR]), tau=event[EV_TAU], work=event[EV_WORK],
                       slip_time=event[EV_SLIP_TIME], steps=int(event[EV_STEPS]),
                       block_steps=int(event[EV_BLOCK_STEPS]), rejected=int(event[EV_REJECTED]),
                       cuts=int(event[EV_CUTS]), vmax=event[EV_VMAX], h_next=event[EV_H_NEXT],
                       err_prev=event[EV_ERR_PREV], traced=int(event[EV_TRACED]),
                       still=int(event[EV_STILL]))


@nb.njit(cache=True)
def continue_event(arrays, t0, n, p, profile, trace, budget):
    """Integrate the event in progress (begin_event) until every block is at rest, or pause.

    Before each step the work spent in this call (block-steps, see above) is compared with
    `budget`: once it is reached the call returns PAUSED, the loop variables back in `event`, and
    the next call continues. A call with budget >= 1 takes at least one step. Otherwise as
    integrate_event (which see); when the event has finished, `event` is BETWEEN and its undo
    log empty. Returns (status, work units spent in this call).
    """
    W, act, flag, event = arrays.W, arrays.act, arrays.flag, arrays.event
    stuck, since, tree = arrays.stuck, arrays.since, arrays.tree
    s = _resume(event)     # the loop variables, by name (a PausedEvent)
    na, nt, yrest, t_far, far = s.na, s.nt, s.yrest, s.t_far, s.far
    tau, work, slip_time, vmax, h_next, err_prev = s.tau, s.work, s.slip_time, s.vmax, s.h_next, s.err_prev
    steps, block_steps, rejected, cuts, traced = s.steps, s.block_steps, s.rejected, s.cuts, s.traced
    still = s.still     # steps in a row that left tau where it was (STALL_STEPS), over paused calls too
    status = OK
    v_limit = RK4_STABILITY / p.dt
    psi_limit = stiff_limit(p.law, v_limit)
    creep_on = possible(p, n)
    used = 0
    # the last step's end state is this step's start, unchanged (steppers.FIRST_LAST): not after a
    # block started or stopped or the step was cut, and not at a call's first step (exact either way)
    unchanged = False
    at_last = (0.0, 0.0)
    recording = recording_history(arrays)     # (decided between events: history.py)
    while na > 0:
        if used >= budget:
            _keep(event, PausedEvent(na=na, nt=nt, yrest=yrest, t_far=t_far, far=far, tau=tau, work=work,
                                     slip_time=slip_time, steps=steps, block_steps=block_steps, rejected=rejected,
                                     cuts=cuts, vmax=vmax, h_next=h_next, err_prev=err_prev, traced=traced,
                                     still=still))
            return PAUSED, used
        if steps >= p.max_steps or tau > p.max_duration:
            status = TOO_LONG
            break
        # -- step-size control: the step from the step start, retried shorter until accepted
        for k in range(na):
            i = act[k]
            W[i, Y0] = W[i, Y]
            W[i, V0] = W[i, V]
            W[i, P0] = W[i, P]
        h = h_next
        tries = 0
        first = FIRST_LAST if unchanged else FIRST_NEW
        at_first = at_last
        while True:
            dwork, dslip, err, at_first, at_last = take_step(W, act, na, n, tau, h, p, yrest, first, at_first)
            first = FIRST_KEPT
            tries += 1
            if traced < trace.shape[0]:
                record(trace, traced, p, W, act, na, tau, h, err)
                traced += 1
            if accepted(p, err, h):
                break
            h = retry_size(p, h, err)
        used += tries * na
        steps += tries - 1          # the rejected tries
        rejected += tries - 1
        h_next, err_prev = next_step_size(p, h, err, err_prev, tries > 1, h_next)
        # -- the earliest transition inside the step (transitions.py), where the step is cut
        for k in range(na):
            # the slip of a sliding block inside the step is the Hermite cubic with these slopes
            i = act[k]
            W[i, HD0] = h * W[i, V0]
            W[i, HD1] = h * W[i, V]
        x_cut = 2.0
        who = -1
        kind = NO_CUT
        for k in range(na):
            i = act[k]
            if W[i, V] <= 0.0 and W[i, V0] > 0.0:
                d0, d1 = velocity_slopes(W, n, i, tau, h, p)
                x = locate(STICK, W, flag, n, i, tau, h, W[i, V0], W[i, V], d0, d1, p)
                if x < x_cut:
                    x_cut, who, kind = x, i, STICK
        for k in range(na):
            i = act[k]
            for j in neighbours(p.geom, i, n):
                # the flag first, here: a call per sliding neighbour (its arrays' reference counts) took a
                # quarter of a 32 x 32 plane's events (docs/plane.md, cost)
                if j != i and flag[j] != SLIDING and above_threshold(W, flag, n, j, tau + h, p):
                    x = locate(ONSET_NEIGHBOUR, W, flag, n, j, tau, h, 0.0, 0.0, 0.0, 0.0, p)
                    if x < x_cut:
                        x_cut, who, kind = x, j, ONSET_NEIGHBOUR
        x_cut, who, kind = loading_cut(x_cut, who, kind, t_far, far, tau, h)
        if kind != NO_CUT and x_cut < 1.0:
            h = x_cut * h
            cuts += 1
            dwork, dslip, _, at_first, at_last = take_step(W, act, na, n, tau, h, p, yrest, FIRST_KEPT, at_first)
            used += na
        if tau + h == tau:
            still += 1
            if still >= STALL_STEPS:
                status = STALLED
                break
        else:
            still = 0
        tau += h
        steps += 1
        block_steps += na
        work += dwork
        slip_time += dslip
        # -- health of the step: finite, and within RK4's stability region (for a full step dt)
        # for the state equation (rate 1/theta = exp(-psi)) and v
        for k in range(na):
            i = act[k]
            v = W[i, V]
            if not (math.isfinite(v) and math.isfinite(W[i, P]) and math.isfinite(W[i, Y])):
                status = NONFINITE
            if v > vmax:
                vmax = v
            if not adaptive(p.method) and rk4_unstable(p.law, v, W[i, P], v_limit, psi_limit) and status == OK:
                status = UNSTABLE
        if status != OK:
            break
        # -- transitions at tau: the located one, then the blocks that stopped
        if kind == ONSET_NEIGHBOUR or kind == ONSET_LOADING:
            na, nt, yrest = _start(arrays, na, nt, t0, p, who, tau, yrest)
        if kind != NO_CUT:
            W[who, V] = 0.0
        m = 0
        nstuck = 0
        for k in range(na):
            i = act[k]
            # a block that started at this very time (in this step, or in one before it cut to no length) has
            # not slid for any time yet, so it cannot have stopped: without this, two blocks on their thresholds
            # within rounding took turns, one starting by loading at the step's start (a cut to no length) while
            # the other, not `pressed` by a rounding, stopped and was due at once again (exp4, N = 5, a = 100, b = 18)
            started = W[i, TS] == tau
            if W[i, V] <= 0.0 and not started and not pressed(W, n, i, tau, p):
                # Blocks never move backward: a block that started this step
                # but could not move keeps its slip.
                if W[i, Y] < W[i, Y0]:
                    W[i, Y] = W[i, Y0]
                nstuck, yrest = _stop(W, flag, stuck, nstuck, i, tau, yrest)
            else:
                act[m] = i
                m += 1
        na = m
        # Resting neighbours of the sliding blocks and of those that just stopped (a step redone up
        # to a located stick differs from the interpolant of the longer step, so a neighbour may
        # have crossed its threshold in the redo).
        for k in range(m + nstuck):
            i = act[k] if k < m else stuck[k - m]
            for j in neighbours(p.geom, i, n):
                if j != i and flag[j] != SLIDING and above_threshold(W, flag, n, j, tau, p):
                    na, nt, yrest = _start(arrays, na, nt, t0, p, j, tau, yrest)
        # -- the hand-back: sliding blocks slow enough to creep stop here and creep from here on
        # (creep.slow_enough, creep.after_event)
        if creep_on and na > 0 and slow_enough(arrays, n, p, na, vmax):
            for k in range(na):
                i = act[k]
                arrays.creep[i, CR_HB] = 1.0
                arrays.creep[i, CR_VN] = W[i, V]
                nstuck, yrest = _stop(W, flag, stuck, nstuck, i, tau, yrest)
            na = 0
        # -- rescheduling, once the set of watched blocks has changed
        unchanged = kind == NO_CUT and nstuck == 0 and na == m
        if not unchanged:
            t_far, far = _reschedule(W, flag, stuck, since, tree, nstuck, n, t0, tau, p)
        _nucleation_step(event, na, nt, tau)
        if recording:
            snapshot(arrays, n, na, nt, tau, na == 0)
    if profile.shape[0] == n:
        profile[:] = 0.0
        for k in range(nt):
            profile[arrays.touched[k]] = W[arrays.touched[k], Y]
    diag = arrays.diag
    _finish_event(W, flag, arrays.touched, nt, since, tree, t0, n, tau, p, work, slip_time, diag)
    diag[D_STEPS] = steps
    diag[D_VMAX] = vmax
    diag[D_BLOCK_STEPS] = block_steps
    diag[D_REJECTED] = rejected
    diag[D_CUTS] = cuts
    diag[D_N_ONSET] = event[EV_N_ONSET]
    diag[D_T_SPREAD] = event[EV_T_SPREAD] if event[EV_T_SPREAD] >= 0.0 else np.nan
    diag[D_T_WIDEST] = event[EV_T_WIDEST]
    diag[D_N_WIDEST] = event[EV_N_WIDEST]
    # the final values too, so that the vector does not depend on where the event was paused
    _keep(event, PausedEvent(na=na, nt=nt, yrest=yrest, t_far=t_far, far=far, tau=tau, work=work,
                             slip_time=slip_time, steps=steps, block_steps=block_steps, rejected=rejected, cuts=cuts,
                             vmax=vmax, h_next=h_next, err_prev=err_prev, traced=traced, still=still))
    clear_log(W, event, arrays.undo)
    event[EV_PHASE] = BETWEEN
    return status, used


@nb.njit(cache=True, inline="always")
def _stop(W, flag, stuck, nstuck, i, tau, yrest):
    """Sliding block i comes to rest at local time tau (a stick, or the hand-back to creep): at rest
    where it is, its slip counted in yrest, and on the list `stuck` of the blocks whose neighbours
    are rescheduled. Returns (nstuck, yrest)."""
    W[i, V] = 0.0
    W[i, TR] = tau
    W[i, YS] = W[i, Y]
    flag[i] = STOPPED
    stuck[nstuck] = i
    return nstuck + 1, yrest + W[i, Y]


@nb.njit(cache=True, inline="always")
def _reschedule(W, flag, stuck, since, tree, nstuck, n, t0, tau, p):
    """After the set of watched blocks changed: the blocks no longer watched by a sliding neighbour
    may only start by loading, back on the schedule with their analytic onset. Returns (t_far, far),
    the earliest such onset."""
    for k in range(nstuck):
        i = stuck[k]
        for j in around(p.geom, i, n):
            tree_set(tree, j, t0[0] + (t0[1] + _loading_onset(W, flag, n, j, tau, p)))
    return _far_onset(W, flag, n, since, tree, t0, tau, p)


@nb.njit(cache=True)
def _finish_event(W, flag, touched, nt, since, tree, t0, n, tau, p, work, slip_time, diag):
    """Summarise the event, bring the touched blocks to its end, reschedule them and their neighbours."""
    slip = 0.0
    first = n
    last = -1
    across_first = n
    across_last = -1
    nslip = 0
    drop = 0.0       # sum of the slipped blocks' force drops by the slip (workspace.py: D_STRESS_DROP)
    # Energy balance in the c-free frame (derivation in docs of workspace.py):
    # dE - W_load = -sum(y F0) + sum(y^2)/2 + l2 sum(dy^2)/2 - nu tau sum(y) + nu int(sum y)
    e_change = 0.0
    gross = abs(work)     # the magnitudes of all the terms: the scale of the residual
    for k in range(nt):
        i = touched[k]
        y = W[i, Y]
        if y > 0.0:
            slip += y
            nslip += 1
            first = min(first, along(p.geom, i))
            last = max(last, along(p.geom, i))
            across_first = min(across_first, across(p.geom, i))
            across_last = max(across_last, across(p.geom, i))
            drop += y * drop_stiffness(p.geom, W, i, n)
        # the non-negative terms (own and spring energies) count alike in both sums
        stored = spring_energy(p.geom, W, flag, i, n, 0.5 * y * y, y)
        e_change += stored - y * W[i, F0]
        gross += stored + abs(y * W[i, F0])
    elastic = e_change     # the terms apart (workspace.py): D_ELASTIC, D_LOAD_WORK
    nu = event_nu(p)
    e_change += -nu * tau * slip + nu * slip_time
    gross += nu * tau * slip + nu * slip_time
    diag[D_DURATION] = tau
    diag[D_SLIP] = slip
    diag[D_FIRST] = first
    diag[D_LAST] = last
    diag[D_ACROSS_FIRST] = across_first
    diag[D_ACROSS_LAST] = across_last
    diag[D_NSLIP] = nslip
    diag[D_WORK] = work
    diag[D_RESIDUAL] = e_change + work
    diag[D_ENERGY_SCALE] = gross
    diag[D_ELASTIC] = elastic
    diag[D_LOAD_WORK] = nu * tau * slip - nu * slip_time
    diag[D_STRESS_DROP] = drop / max(nslip, 1)
    # The touched blocks move to the end time (loading, state grown since they
    # stopped); their untouched neighbours stay at t0, which is just as valid.
    # Then the slip changes the forces (free ends: an end block has one spring).
    # A law whose loader stands still during events ends them at t0 (no loading time).
    elapsed = tau if loader_moves(p.law) else 0.0
    for k in range(nt):
        i = touched[k]
        W[i, F0] += nu * tau
        W[i, P] = rest_state(p.law, W[i, P], tau - W[i, TR])
        since[i, 0] = t0[0]
        since[i, 1] = t0[1]
        advance_clock(since[i], elapsed)
    for k in range(nt):
        i = touched[k]
        y = W[i, Y]
        W[i, F0] -= stiffness(p.geom, i, n) * y
        for j in neighbours(p.geom, i, n):
            if j != i:
                W[j, F0] += coupling(p.geom, i, j) * y
    for k in range(nt):
        i = touched[k]
        W[i, Y] = 0.0
        W[i, YS] = 0.0
        W[i, V] = 0.0
        W[i, TR] = 0.0
        flag[i] = UNTOUCHED
    for k in range(nt):
        i = touched[k]
        for j in around(p.geom, i, n):
            tree_set(tree, j, onset_key(W, since, j, p))
