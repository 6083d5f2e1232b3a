"""Quasi-static creep: the third scene of rate-and-state friction, beside rest and inertial events.

Where a block's stiffness exceeds its law's weakening (the aging law: b below 1 + 2 l^2 for an
interior block), a block that reaches its static threshold does not rupture: it creeps, holding its
force equal to its friction, with inertia negligible, on time scales of 1e6 to 1e10. Its neighbours
at rest load up through its slip; when one of them reaches its threshold it joins the creeping
cluster, and a cluster too soft for its law (its stiffness matrix minus the weakening no longer
positive definite) hands over to an inertial event. Equations and criteria: docs/numerics.md,
"Quasi-static creep".

The creep phase is part of the between-events state. Creeping blocks (the set C) keep, like blocks
at rest, their force W[i, F0] and state W[i, P] at their time since[i]; besides, their velocity, the
episode they belong to, and the step size live in the creep arrays below, which a checkpoint keeps
(Workspace.creep_state). Creep advances all creeping blocks together by backward-Euler steps of
the index-1 system "force = friction, psi' = g(v, psi)", with the step size controlled by an error
estimate of the state, cut where a block at rest reaches its threshold (located by bisection, as in
events) and where the onset schedule's next block starts by loading alone. A block whose creep
velocity comes out negative stops (an active-set pass). Creeping blocks and their resting
neighbours are off the onset schedule (key inf) while they creep.

An episode of creep begins when a block starts to creep with no creeping neighbour; a block that
starts beside a creeping one joins its episode (its left neighbour's, if both creep). It ends when
its last block has stopped (STOPPED) or has been taken by an inertial event (RUPTURED); the kernel
then reports it as a row of its own (kind 1, chain.simulate).

While an event runs, creep elsewhere waits: an event lasts 1e0 to 1e3 time units, creep moves
1e-9 per unit, and the next creep step covers the event's duration (each block steps from its own
time since[i]), with the event's slip already in the forces.
"""
import math

import numba as nb
import numpy as np

from .geometry import (CREEPING, SLIDING_NOW, across, along, around, cluster, coupling, creep_force, creep_load,
                       creep_solve, creeping, fastest_creep, max_stiffness, neighbours, stable, stiffness)
from .laws import (creep_state, creep_weakening, creeps, friction, friction_slopes, onset_delay, rest_state, state_rate,
                   threshold)
from .schedule import advance_clock, materialize, onset_key, tree_min, tree_set
from .workspace import (D_ACROSS_FIRST, D_ACROSS_LAST, E_ACROSS_FIRST, E_ACROSS_LAST, CR_DIAG, CR_DPSI, CR_DU,
                        CR_EP, CR_H, CR_HB, CR_LEFT, CR_PSI, CR_RES, CR_SERIAL, CR_UPPER, CR_V,
                        CR_VN, CR_W, CS_DIRTY, CS_ENDED, CS_FRESH, CS_H, CS_NCREEP, CS_SERIAL, CS_T_HI, CS_T_LO,
                        E_ACTIVE, E_BLOCK_STEPS, E_END_HI, E_END_LO, E_EPICENTER, E_FIRST, E_LAST, E_LOAD_WORK,
                        E_NBLOCKS, E_RUNNING, E_RUPTURED, E_SERIAL, E_SLIP, E_START_HI, E_START_LO, E_STATE, E_STOPPED,
                        E_VMAX, E_WORK, F0, P, D_BLOCK_STEPS, D_DURATION, D_ELASTIC, D_ENDING, D_ENERGY_SCALE, D_FIRST,
                        D_KIND, D_LAST, D_LOAD_WORK, D_NSLIP, D_RESIDUAL, D_SLIP, D_STRESS_DROP, D_T_WIDEST,
                        D_T_SPREAD, D_VMAX, D_WORK, EV_NT, KIND_CREEP, PAUSED, V)

# what continue_creep returns besides PAUSED
REACHED = 10      # creep is integrated up to the onset of the schedule's next block (or nothing creeps)
ENDED = 11        # episodes have ended: their rows wait (CS_ENDED), chain.simulate reports them
HANDOVER = 12     # a cluster became too soft to creep: the block `who` starts an inertial event there

_NEWTON = 40      # Newton iterations of one creep step before the step is halved
_BISECT = 60      # halvings locating an onset inside a creep step (2^-60 of the step)
_GROW = 5.0       # the step grows at most fivefold, ...
_SHRINK = 0.2     # ... and shrinks at most fivefold, per step


@nb.njit(cache=True)
def possible(p, n):
    """Some block of this chain can creep under these parameters: its law creeps, and the stiffest
    single block (interior 1 + 2 l^2, at a free end 1 + l^2, alone 1) is stiffer than the law's
    weakening as it starts from rest (v = 0; the aging law's does not depend on the state, the slip
    law's is -inf). Otherwise no cluster ever creeps (a cluster is never stiffer than its stiffest
    block alone), and the kernels run exactly as without a creep phase."""
    if not creeps(p.law):
        return False
    k_max = max_stiffness(p.geom, n)
    return creep_weakening(p.law, 0.0, 0.0) < k_max


@nb.njit(cache=True)
def alone_creeps(arrays, n, p, j):
    """Block j, starting from rest with its state, may creep alone: stiffer than its weakening."""
    return stiffness(p.geom, j, n) > creep_weakening(p.law, 0.0, arrays.W[j, P])


@nb.njit(cache=True)
def loaded_past_threshold(p, n, psi):
    """A block on its threshold, at rest with state psi, is loaded faster than its threshold grows
    over an inertial period: it starts to move (creep). Otherwise it is on its threshold only for an
    instant (an event's block that stuck on it, its threshold then outrunning the loader), and the
    kernels treat it as they always have: an event, in which it stays pressed without slipping."""
    dt = 2.0 * math.pi / math.sqrt(max_stiffness(p.geom, n))
    return p.nu * dt > threshold(p.law, rest_state(p.law, psi, dt)) - threshold(p.law, psi)


@nb.njit(cache=True)
def cluster_of(C, flag, lst, seen, n, p, j):
    """The number m of blocks in the cluster of creeping blocks around block j (j counted as creeping),
    lst[:m] holding them in increasing order (lst, seen: WorkArrays.cluster and .seen; the work arrays go to
    the hot calls one by one, not as the record, whose every array each call counts a reference of)."""
    m = cluster(p.geom, C, flag, CREEPING, n, j, lst, seen)
    forget(lst, seen, m)
    return m


@nb.njit(cache=True)
def forget(lst, seen, m):
    """Clear the marks a cluster lst[:m] left in seen."""
    for k in range(m):
        seen[lst[k]] = 0


@nb.njit(cache=True)
def _watched(C, n, j, p):
    """Block j is creeping or beside a creeping block: off the onset schedule."""
    for k in around(p.geom, j, n):
        if creeping(C, k):
            return True
    return False


@nb.njit(cache=True)
def creeping_list(C, cs, crept, n):
    """The number m of creeping blocks, crept[:m] holding them in increasing order (made again after blocks
    joined or left: O(n) per change of the set, not per step). C, cs, crept: the work arrays creep, cstate,
    crept."""
    if cs[CS_DIRTY] != 0.0:
        m = 0
        for i in range(n):
            if C[i, CR_EP] != 0.0:
                crept[m] = i
                m += 1
        cs[CS_DIRTY] = 0.0
    return int(cs[CS_NCREEP])


@nb.njit(cache=True, inline="always")
def _first_visit(C, n, p, i, j):
    """Resting block j beside creeping block i is met here first in a pass over the creeping blocks
    in increasing order: i is its creeping neighbour of lowest index (a block between two creeping ones is met once)."""
    if j == i or creeping(C, j):
        return False
    for q in neighbours(p.geom, j, n):
        if q < i and q != j and creeping(C, q):
            return False
    return True


@nb.njit(cache=True)
def rekey(arrays, n, p, j):
    """Block j's onset key: inf while creep watches it, else its onset by loading alone."""
    if _watched(arrays.creep, n, j, p):
        tree_set(arrays.tree, j, np.inf)
    else:
        tree_set(arrays.tree, j, onset_key(arrays.W, arrays.since, j, p))


@nb.njit(cache=True)
def off_schedule(arrays, n, p):
    """Creeping blocks and their neighbours off the onset schedule (after it was built anew)."""
    for j in range(n):
        if _watched(arrays.creep, n, j, p):
            tree_set(arrays.tree, j, np.inf)


@nb.njit(cache=True)
def _new_episode(E, cs, t, j, g):
    """A free slot of the episode table for an episode starting at block j at time t (two floats)."""
    slot = 0
    while E[slot, E_STATE] != 0.0:
        slot += 1
    E[slot, :] = 0.0
    E[slot, E_STATE] = E_RUNNING
    E[slot, E_START_HI] = t[0]
    E[slot, E_START_LO] = t[1]
    E[slot, E_EPICENTER] = j
    E[slot, E_FIRST] = E[slot, E_LAST] = along(g, j)
    E[slot, E_ACROSS_FIRST] = E[slot, E_ACROSS_LAST] = across(g, j)
    cs[CS_SERIAL] += 1.0
    E[slot, E_SERIAL] = cs[CS_SERIAL]
    return slot


@nb.njit(cache=True)
def join(arrays, n, p, j, v0, t):
    """Block j starts to creep at time t (two floats; its F0 and P hold there) with velocity v0:
    into the episode of a creeping neighbour (the first in the geometry's order: the left one), or a new episode."""
    C, E, cs, W, since = arrays.creep, arrays.episodes, arrays.cstate, arrays.W, arrays.since
    if cs[CS_NCREEP] == 0.0:
        # a new creep phase: its first step from the state's own time scale
        cs[CS_H] = p.creep_tol * math.exp(W[j, P]) + 2.0 * math.pi / math.sqrt(max_stiffness(p.geom, n))
    if cs[CS_NCREEP] == 0.0 or (t[0] - cs[CS_T_HI]) + (t[1] - cs[CS_T_LO]) > 0.0:
        # the creep's clock: never behind a creeping block's own time (the others step from theirs)
        cs[CS_T_HI] = t[0]
        cs[CS_T_LO] = t[1]
    slot = -1
    for k in neighbours(p.geom, j, n):
        if k != j and creeping(C, k):
            slot = int(C[k, CR_EP]) - 1
            break
    if slot < 0:
        slot = _new_episode(E, cs, t, j, p.geom)
    C[j, CR_EP] = slot + 1
    C[j, CR_V] = v0
    cs[CS_FRESH] = 1.0
    E[slot, E_ACTIVE] += 1.0
    if C[j, CR_SERIAL] != E[slot, E_SERIAL]:
        C[j, CR_SERIAL] = E[slot, E_SERIAL]
        E[slot, E_NBLOCKS] += 1.0
    cs[CS_NCREEP] += 1.0
    cs[CS_DIRTY] = 1.0
    for k in around(p.geom, j, n):
        if k != j and not creeping(C, k):
            materialize(W, since, k, t, p)      # a watched neighbour stays at the creep's time
        tree_set(arrays.tree, k, np.inf)


@nb.njit(cache=True)
def leave(arrays, n, p, i, t, outcome):
    """Block i stops creeping at time t (two floats): it stopped (outcome E_STOPPED) or an event took
    it (E_RUPTURED). Its episode ends with its last block."""
    C, E, cs = arrays.creep, arrays.episodes, arrays.cstate
    slot = int(C[i, CR_EP]) - 1
    C[i, CR_EP] = 0.0
    C[i, CR_V] = 0.0
    cs[CS_NCREEP] -= 1.0
    cs[CS_DIRTY] = 1.0
    E[slot, E_ACTIVE] -= 1.0
    if E[slot, E_ACTIVE] == 0.0:
        E[slot, E_STATE] = outcome
        E[slot, E_END_HI] = t[0]
        E[slot, E_END_LO] = t[1]
        cs[CS_ENDED] += 1.0
    for k in around(p.geom, i, n):
        rekey(arrays, n, p, k)


@nb.njit(cache=True)
def _step_sizes(C, since, lst, m, t, h):
    """CR_H of every creeping block (lst[:m]): from its own time to t + h (they differ after an event)."""
    for k in range(m):
        i = lst[k]
        C[i, CR_H] = h + ((t[0] - since[i, 0]) + (t[1] - since[i, 1]))


@nb.njit(cache=True)
def _newton(arrays, n, p):
    """One backward-Euler step of every creeping block to its CR_H: the velocities CR_VN that put
    every creeping block's force at the step's end on its friction, with psi from its own state
    equation (creep_state). Tridiagonal Newton from CR_V, and if that fails from rest: a law whose
    friction first rises and then falls with v (the slip law) has a second, fast root, and the
    creep's is the one next to rest, which Newton reaches from v = 0 (its residual is convex in v
    there). Returns -1, or if neither converges with every pivot negative (the step's system is no
    longer that of a creeping cluster) the block where the iteration from rest failed: the first
    whose pivot is not negative (where the cluster became too soft), else the last that had not
    converged."""
    C = arrays.creep
    lst = arrays.crept
    m_c = creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)
    for k in range(m_c):
        i = lst[k]
        C[i, CR_VN] = C[i, CR_V]
    if _newton_from(arrays, n, p, m_c) < 0:
        return -1
    for k in range(m_c):
        C[lst[k], CR_VN] = 0.0
    return _newton_from(arrays, n, p, m_c)


@nb.njit(cache=True)
def _newton_from(arrays, n, p, m_c):
    """_newton's iteration from CR_VN: -1 if it converged, else the block where it failed.

    Converged: every update below 1e-12 of v or below what the rounding of the forces moves v by, or,
    when the iterations are spent, every block's force balanced to that rounding (1e-14 of the largest
    force). The second is the first's limit where the cluster is nearly too soft: the rounding of one
    block's force then moves every velocity of the run through its smallest pivot, not the block's own
    (a cluster of 9 blocks 0.1 above the loss of stability at l = 12: forces balanced to 1e-13 of 371,
    updates flipping sign at 1e-13 for ever), and without it such a cluster was handed to an event that
    slid at its creep velocities until integrator.max_duration."""
    C, W = arrays.creep, arrays.W
    lst = arrays.crept
    # the rounding of the cluster's forces (~1e-14 of the largest) reaches every block through the
    # springs: the scale of the convergence test
    scale = 1.0
    for k in range(m_c):
        scale = max(scale, abs(W[lst[k], F0]))
    balanced = False
    worst = -1
    for it in range(_NEWTON):
        balanced = True
        # near the fold of a cluster about to become too soft Newton converges only linearly: the
        # last iterations accept an update below 1e-9 of v
        rel = 1e-12 if it < _NEWTON - 5 else 1e-9
        for k in range(m_c):
            i = lst[k]
            h = C[i, CR_H]
            v = C[i, CR_VN]
            psi, dpsi = creep_state(p.law, W[i, P], v, h)
            C[i, CR_PSI] = psi
            C[i, CR_DPSI] = dpsi
            C[i, CR_DU] = h * v
        worst = -1
        for k in range(m_c):
            i = lst[k]
            h = C[i, CR_H]
            v = C[i, CR_VN]
            psi = C[i, CR_PSI]
            force = creep_force(p.geom, C, W, i, n, p.nu, h)
            f_v, f_psi = friction_slopes(p.law, v, psi)
            r = -(force - friction(p.law, v, psi))
            balanced = balanced and abs(r) <= 1e-14 * scale
            C[i, CR_DIAG] = -stiffness(p.geom, i, n) * h - f_v - f_psi * C[i, CR_DPSI]
            C[i, CR_RES] = r
        bad = creep_solve(p.geom, C, lst, m_c, n)
        if bad >= 0:
            return bad
        for k in range(m_c - 1, -1, -1):
            i = lst[k]
            delta = C[i, CR_UPPER]
            v = C[i, CR_VN] + delta
            C[i, CR_VN] = v
            # converged: the update is below 1e-12 of v, or below what the rounding of the forces
            # moves v by
            if not (abs(delta) <= rel * abs(v) + 1e-14 * scale / abs(C[i, CR_DIAG])):
                worst = i
        if worst < 0:
            break
    if worst >= 0 and not balanced:
        return worst
    for k in range(m_c):
        i = lst[k]
        C[i, CR_PSI], C[i, CR_DPSI] = creep_state(p.law, W[i, P], C[i, CR_VN], C[i, CR_H])
        C[i, CR_DU] = C[i, CR_H] * C[i, CR_VN]
    return -1


@nb.njit(cache=True)
def _excess(W, C, since, n, p, j, t, h, x):
    """Force above the static threshold of resting block j at fraction x of the creep step of size
    h from time t (two floats): loading since its own time, and x of its creeping neighbours'
    slips over the step (backward Euler: linear in time)."""
    dt = (t[0] - since[j, 0]) + (t[1] - since[j, 1]) + x * h
    return W[j, F0] + p.nu * dt + creep_load(p.geom, C, j, n, x) - threshold(p.law, rest_state(p.law, W[j, P], dt))


@nb.njit(cache=True)
def _locate(W, C, since, n, p, j, t, h):
    """The earliest fraction of the step by which resting block j has reached its threshold (it has
    by the step's end), by bisection."""
    if _excess(W, C, since, n, p, j, t, h, 0.0) >= 0.0:
        return 0.0
    lo = 0.0
    hi = 1.0
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        if _excess(W, C, since, n, p, j, t, h, mid) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@nb.njit(cache=True)
def _overrun(arrays, n, p, t, h):
    """A block that stopped creeping in this step (CR_LEFT) is past its threshold again by the step's
    end: the step is too long for the active set that stopped it (its onset is looked for only from the
    next step, so this step must not carry it past its threshold)."""
    C = arrays.creep
    for j in range(n):
        if C[j, CR_LEFT] != 0.0 and not creeping(C, j):
            if _excess(arrays.W, C, arrays.since, n, p, j, t, h, 1.0) > 0.0:
                return True
    return False


@nb.njit(cache=True)
def _rate(law, v, psi):
    """The state's rate (a call of its own: numba's inliner mislabels two in one loop)."""
    return state_rate(law, v, psi)


@nb.njit(cache=True)
def _error(arrays, n, p):
    """The step's error norm: half the change over the step of the state's rate and of the
    velocity (backward Euler's local error), in psi, relative to integrator.creep_tol; the slip's
    error counts as the force it makes (K_ii du) over the friction's slope in psi."""
    C, W = arrays.creep, arrays.W
    err = 0.0
    lst = arrays.crept
    for k in range(creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)):
        i = lst[k]
        g_end = _rate(p.law, C[i, CR_VN], C[i, CR_PSI])
        g_start = _rate(p.law, C[i, CR_V], W[i, P])
        dv = C[i, CR_VN] - C[i, CR_V]
        w = friction_slopes(p.law, C[i, CR_VN], C[i, CR_PSI])[1]
        e = 0.5 * C[i, CR_H] * (abs(g_end - g_start) + stiffness(p.geom, i, n) * abs(dv) / w) / p.creep_tol
        err = max(err, e)
    return err


@nb.njit(cache=True)
def _commit(arrays, n, p, t_new):
    """The step's end becomes the state: creeping blocks' force, psi, velocity and time; their resting
    neighbours brought to t_new with the creeping blocks' slip in their force; episode statistics and
    energy. A block's slip is linear in time over its own step (since[i] to t_new), so is its force, and
    the friction work is the trapezoid of the force at the step's two ends: exactly the loader's work
    less the elastic change along that path (docs/numerics.md, "Energy of creep"); the loader's work
    counts from the episode's start, the slip at the step's middle (workspace.E_LOAD_WORK)."""
    C, E, W, since = arrays.creep, arrays.episodes, arrays.W, arrays.since
    lst = arrays.crept
    m = creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)
    for k in range(m):
        i = lst[k]
        C[i, CR_RES] = creep_force(p.geom, C, W, i, n, p.nu, C[i, CR_H])
    for k in range(m):
        i = lst[k]
        for j in neighbours(p.geom, i, n):
            if _first_visit(C, n, p, i, j):
                materialize(W, since, j, t_new, p)
                for q in neighbours(p.geom, j, n):
                    if q != j and creeping(C, q):
                        W[j, F0] += coupling(p.geom, j, q) * C[q, CR_DU]
    for k in range(m):
        i = lst[k]
        force = W[i, F0]        # at the step's start
        W[i, F0] = C[i, CR_RES]
        W[i, P] = C[i, CR_PSI]
        since[i, 0] = t_new[0]
        since[i, 1] = t_new[1]
        v = C[i, CR_VN]
        C[i, CR_V] = v
        slot = int(C[i, CR_EP]) - 1
        du = C[i, CR_DU]
        E[slot, E_WORK] += 0.5 * (force + C[i, CR_RES]) * du
        E[slot, E_LOAD_WORK] += p.nu * du * ((t_new[0] - E[slot, E_START_HI]) + (t_new[1] - E[slot, E_START_LO])
                                             - 0.5 * C[i, CR_H])
        E[slot, E_BLOCK_STEPS] += 1.0
        if du > 0.0:
            E[slot, E_SLIP] += du
            E[slot, E_FIRST] = min(E[slot, E_FIRST], along(p.geom, i))
            E[slot, E_LAST] = max(E[slot, E_LAST], along(p.geom, i))
            E[slot, E_ACROSS_FIRST] = min(E[slot, E_ACROSS_FIRST], across(p.geom, i))
            E[slot, E_ACROSS_LAST] = max(E[slot, E_ACROSS_LAST], across(p.geom, i))
        if v > E[slot, E_VMAX]:
            E[slot, E_VMAX] = v


@nb.njit(cache=True)
def _solve(arrays, n, p, t, h):
    """The creep step from time t (two floats) by h: Newton, and every block whose velocity comes out
    negative stops at t (it is at rest instead: an active-set pass), until none does. Returns
    (converged, work in block-steps, blocks stopped, the block where Newton failed or -1)."""
    C, cs = arrays.creep, arrays.cstate
    work = 0
    stopped = 0
    while cs[CS_NCREEP] > 0.0:
        m = creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)
        _step_sizes(C, arrays.since, arrays.crept, m, t, h)
        work += m
        bad = _newton(arrays, n, p)
        if bad >= 0:
            return False, work, stopped, bad
        backward = False
        for k in range(m):
            i = arrays.crept[k]     # (leave changes the set, not this list, until it is made again)
            if C[i, CR_VN] < 0.0:
                leave(arrays, n, p, i, t, E_STOPPED)
                C[i, CR_LEFT] = 1.0
                stopped += 1
                backward = True
        if not backward:
            break
    return True, work, stopped, -1


@nb.njit(cache=True)
def _accelerating(arrays, n, h, inertial):
    """The fastest of the creeping blocks whose velocity grows by e within an inertial period over the step just
    solved (v / (dv/dt) < inertial), or -1: where the creep runs away, the block that leads (not the first of the
    list, which would put every such epicenter on one side of a cluster)."""
    C = arrays.creep
    who = -1
    for k in range(creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)):
        i = arrays.crept[k]
        grow = C[i, CR_VN] - C[i, CR_V]
        if grow > 0.0 and C[i, CR_VN] * h < inertial * grow and (who < 0 or C[i, CR_VN] > C[who, CR_VN]):
            who = i
    return who


@nb.njit(cache=True)
def _leading(arrays, n, p, bad):
    """The epicenter where a step's Newton failed at block `bad` (its cluster too soft to creep, at its fold): the
    fastest block of the cluster at the step's start (the order of the sweep, which decides where a pivot first
    turns non-negative, would put it at one end of every cluster); `bad` itself if none of it moves."""
    C = arrays.creep
    if not creeping(C, bad):
        return bad
    who = bad
    for k in range(cluster_of(C, arrays.flag, arrays.cluster, arrays.seen, n, p, bad)):
        i = arrays.cluster[k]
        if C[i, CR_V] > C[who, CR_V]:
            who = i
    return who


@nb.njit(cache=True)
def continue_creep(arrays, clock, n, p, budget):
    """Advance the creeping blocks by steps until something needs the caller. Returns
    (code, work spent, block): REACHED when the creep has reached the schedule's next onset by
    loading alone (or nothing creeps), the caller starts that block; ENDED when episodes have ended
    (cstate[CS_ENDED] of them, their rows wait in the episode table); HANDOVER when `block` starts an
    inertial event (its cluster too soft, or the creep's steps down to inertia's time scale) at the
    creep's time; PAUSED when the budget (block-steps, as events count them) ran out before a step.
    `clock` follows the creep's time."""
    C, cs, W, since, tree = arrays.creep, arrays.cstate, arrays.W, arrays.since, arrays.tree
    inertial = 2.0 * math.pi / math.sqrt(max_stiffness(p.geom, n))
    t = np.empty(2)
    t_new = np.empty(2)
    used = 0
    while True:
        if cs[CS_ENDED] > 0.0:
            return ENDED, used, -1
        t[0], t[1] = cs[CS_T_HI], cs[CS_T_LO]
        if (t[0] - clock[0]) + (t[1] - clock[1]) > 0.0:
            clock[0], clock[1] = t[0], t[1]
        if cs[CS_NCREEP] == 0.0:
            return REACHED, used, -1
        key, far = tree_min(tree)
        t_far = np.inf
        if key != np.inf:
            t_far = (since[far, 0] - t[0]) + (since[far, 1] - t[1]) + onset_delay(p.law, W[far, F0], W[far, P], p.nu)
        if t_far < inertial:
            # the next onset is within one inertial period: creep moves nothing in that time, and
            # each creeping block steps from its own time later on
            return REACHED, used, -1
        if used >= budget:
            return PAUSED, used, -1
        stopped = 0      # blocks stopped in this step (their CR_LEFT is scratch of the step)
        if cs[CS_FRESH] != 0.0:
            # a block joined (from rest, or handed back by an event): every creeping velocity from a
            # step of inertia's time scale, so that the error estimate starts from the creep's own
            # velocities and not from the jump of a block's velocity to them
            cs[CS_FRESH] = 0.0
            solved, work, stopped, bad = _solve(arrays, n, p, t, inertial)
            used += work
            if not solved:
                return HANDOVER, used, bad
            for k in range(creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)):
                i = arrays.crept[k]
                C[i, CR_V] = C[i, CR_VN]
        if cs[CS_NCREEP] == 0.0:
            C[:, CR_LEFT] = 0.0
            continue
        # -- the step, retried shorter until its error is accepted
        h = min(cs[CS_H], t_far)
        err = 0.0
        while True:
            solved, work, gone, bad = _solve(arrays, n, p, t, h)
            used += work
            stopped += gone
            if solved and cs[CS_NCREEP] == 0.0:
                break
            err = _error(arrays, n, p) if solved else np.inf
            if h <= inertial:
                break
            if err <= 1.0:
                if stopped == 0 or not _overrun(arrays, n, p, t, h):
                    break
                h = max(0.5 * h, inertial)
                continue
            # never below inertia's time scale, which the quasi-static equations do not resolve
            h = max(h * max(_SHRINK, 0.9 / math.sqrt(err)), h * 0.25, inertial)
        if not solved:
            # no creep: the cluster became too soft where Newton failed
            return HANDOVER, used, _leading(arrays, n, p, bad)
        # creep that accelerates on inertia's time scale is no longer quasi-static: an event
        who = _accelerating(arrays, n, h, inertial)
        if who >= 0:
            return HANDOVER, used, who
        # an error that wants steps shorter than inertia's time scale from creep that does not accelerate on it (a
        # velocity relaxing onto the creep's own, over a / (K - b), faster than inertia): the step is taken at the
        # inertial period, which the quasi-static equations do not resolve below; an event there could never end,
        # its blocks sliding at their creep velocities (slow_enough), and the task failed at max_duration
        if cs[CS_NCREEP] == 0.0:
            C[:, CR_LEFT] = 0.0
            continue
        # at most the time the loader takes to move one unit of length (steady creep has no error
        # to bound its step)
        cs[CS_H] = min(max(h * min(_GROW, max(_SHRINK, 0.9 / math.sqrt(max(err, 1e-10)))), inertial), 1.0 / p.nu)
        # -- the earliest onset inside the step: a resting neighbour of a creeping block, or the
        # schedule's next block by loading alone
        x_cut = 2.0
        who = -1
        lst = arrays.crept
        for k in range(creeping_list(arrays.creep, arrays.cstate, arrays.crept, n)):
            i = lst[k]
            for j in neighbours(p.geom, i, n):
                if not _first_visit(C, n, p, i, j):
                    continue
                if C[j, CR_LEFT] != 0.0:
                    C[j, CR_LEFT] = 0.0     # stopped in this step: its onset is looked for from the next
                    continue
                if _excess(W, C, since, n, p, j, t, h, 1.0) > 0.0:
                    x = _locate(W, C, since, n, p, j, t, h)
                    if x < x_cut:
                        x_cut, who = x, j
        if stopped > 0:
            C[:, CR_LEFT] = 0.0         # (scratch of this step only)
        far_first = False
        if t_far <= h and t_far / h < x_cut:
            x_cut, who, far_first = t_far / h, far, True
        if who >= 0 and x_cut < 1.0:
            if x_cut == 0.0:
                h = 0.0
            else:
                h *= x_cut
                solved, work, _, bad = _solve(arrays, n, p, t, h)
                used += work
                if not solved:
                    return HANDOVER, used, _leading(arrays, n, p, bad)
        if h > 0.0:
            t_new[0], t_new[1] = t[0], t[1]
            advance_clock(t_new, h)
            _commit(arrays, n, p, t_new)
            cs[CS_T_HI], cs[CS_T_LO] = t_new[0], t_new[1]
            clock[0], clock[1] = t_new[0], t_new[1]
        if who < 0 or far_first:
            continue
        # -- a resting neighbour starts: it creeps with its cluster, or the cluster ruptures
        t[0], t[1] = cs[CS_T_HI], cs[CS_T_LO]
        m = cluster_of(C, arrays.flag, arrays.cluster, arrays.seen, n, p, who)
        for k in range(m):
            i = arrays.cluster[k]
            C[i, CR_W] = creep_weakening(p.law, C[i, CR_V] if creeping(C, i) else 0.0, W[i, P])
        if not stable(p.geom, C, n, arrays.cluster, m):
            return HANDOVER, used, who
        join(arrays, n, p, who, 0.0, t)


@nb.njit(cache=True)
def _fastest_sliding(W, act, flag, C, lst, seen, n, p, na):
    """slow_enough's clusters of sliding blocks (act[:na]), each met once (arrays.seen marks the ones met, the
    caller clears it): the fastest creep one of them can sustain, or -1 if one cannot creep, or a block of it
    moves faster than that."""
    fastest = 0.0
    for k in range(na):
        if seen[act[k]] != 0:
            continue        # its cluster was met already
        m = cluster(p.geom, C, flag, SLIDING_NOW, n, act[k], lst, seen)
        for q in range(m):
            i = lst[q]
            C[i, CR_W] = creep_weakening(p.law, W[i, V], W[i, P])
        if not stable(p.geom, C, n, lst, m):
            return -1.0
        for q in range(m):
            i = lst[q]
            C[i, CR_W] = creep_weakening(p.law, 0.0, W[i, P])
        fastest_creep(p.geom, C, n, p.nu, lst, m)
        for q in range(m):
            i = lst[q]
            if W[i, V] > C[i, CR_RES]:
                return -1.0
            fastest = max(fastest, C[i, CR_RES])
    return fastest


@nb.njit(cache=True)
def slow_enough(arrays, n, p, na, vmax):
    """Every sliding block of the event in progress (act[:na]) could creep instead: each run of
    sliding blocks is a stable cluster at its blocks' weakening there, and each block moves forward
    no faster than the fastest creep its cluster can sustain (fastest_creep, at the weakening from
    rest: a law whose weakening grows with v creeps slower than it), while the event, its
    largest velocity so far `vmax`, has been faster than that somewhere (an event that a cluster too
    soft to creep handed over must first leave the creep's range: handed back before, it would find
    no creep again). The event then hands its blocks back to creep; the kinetic energy it drops is
    at most that of those creep velocities."""
    W, act = arrays.W, arrays.act
    for k in range(na):
        if not W[act[k], V] >= 0.0:
            return False
    fastest = _fastest_sliding(W, act, arrays.flag, arrays.creep, arrays.cluster, arrays.seen, n, p, na)
    for k in range(na):
        arrays.seen[act[k]] = 0
    if not fastest >= 0.0:
        return False
    return vmax > fastest


@nb.njit(cache=True)
def after_event(arrays, n, p, onset, clock):
    """The event that just ended (its touched blocks, event.py), from `onset` to `clock` (two-float
    times), meets the creep: creeping blocks it took leave their episodes (RUPTURED) at its onset,
    blocks it handed back (CR_HB) start to creep with their velocity, the creep goes on from the
    event's end, and the blocks around it are rescheduled.

    The event took its blocks at its onset, not when each started to slide in it: from the onset on
    the event integrates them (a block at rest in its equations, its state healing from the onset,
    until its force reaches the threshold), and creep, which waits while an event runs, moves them
    no more; a hand-over slides the cluster's blocks from the onset anyway. So an episode taken over
    ends where the event's row begins, and the two rows do not overlap in time."""
    C, cs, touched = arrays.creep, arrays.cstate, arrays.touched
    nt = int(arrays.event[EV_NT])
    t = np.empty(2)
    for k in range(nt):
        i = touched[k]
        if creeping(C, i):
            leave(arrays, n, p, i, onset, E_RUPTURED)
    for k in range(nt):
        i = touched[k]
        if C[i, CR_HB] != 0.0:
            C[i, CR_HB] = 0.0
            t[0], t[1] = arrays.since[i, 0], arrays.since[i, 1]
            join(arrays, n, p, i, C[i, CR_VN], t)
    if cs[CS_NCREEP] > 0.0:
        cs[CS_T_HI], cs[CS_T_LO] = clock[0], clock[1]
    for k in range(nt):
        i = touched[k]
        for j in around(p.geom, i, n):
            rekey(arrays, n, p, j)


@nb.njit(cache=True)
def report(arrays, n, out_t, out_epicenter, out_diag, k):
    """The next ended episode into row k of the output (kind 1); returns the rows written (0 or 1,
    an episode that slipped nothing is dropped) and frees its slot."""
    E, cs = arrays.episodes, arrays.cstate
    for slot in range(E.shape[0]):
        state = E[slot, E_STATE]
        if state == E_STOPPED or state == E_RUPTURED:
            E[slot, E_STATE] = 0.0
            cs[CS_ENDED] -= 1.0
            if not E[slot, E_SLIP] > 0.0:
                return 0
            out_t[k] = E[slot, E_START_HI] + E[slot, E_START_LO]
            out_epicenter[k] = int(E[slot, E_EPICENTER])
            out_diag[k, :] = 0.0
            out_diag[k, D_DURATION] = ((E[slot, E_END_HI] - E[slot, E_START_HI])
                                       + (E[slot, E_END_LO] - E[slot, E_START_LO]))
            out_diag[k, D_SLIP] = E[slot, E_SLIP]
            out_diag[k, D_FIRST] = E[slot, E_FIRST]
            out_diag[k, D_LAST] = E[slot, E_LAST]
            out_diag[k, D_ACROSS_FIRST] = E[slot, E_ACROSS_FIRST]
            out_diag[k, D_ACROSS_LAST] = E[slot, E_ACROSS_LAST]
            out_diag[k, D_NSLIP] = E[slot, E_NBLOCKS]
            out_diag[k, D_VMAX] = E[slot, E_VMAX]
            out_diag[k, D_BLOCK_STEPS] = E[slot, E_BLOCK_STEPS]
            out_diag[k, D_WORK] = E[slot, E_WORK]
            out_diag[k, D_LOAD_WORK] = E[slot, E_LOAD_WORK]
            # not an episode's own: the balance closes over a run (workspace.py)
            out_diag[k, D_ELASTIC] = out_diag[k, D_RESIDUAL] = out_diag[k, D_ENERGY_SCALE] = np.nan
            out_diag[k, D_STRESS_DROP] = np.nan     # (its blocks' slips are not kept one by one)
            out_diag[k, D_T_SPREAD] = out_diag[k, D_T_WIDEST] = np.nan     # (an event's nucleation: none here)
            out_diag[k, D_KIND] = KIND_CREEP
            out_diag[k, D_ENDING] = 1.0 if state == E_STOPPED else 2.0
            return 1
    return 0
