"""Work arrays shared by the event kernels, and the codes they return.

The float work array W has one row per block and one column per per-block
quantity (index constants below), so that everything the integrator touches for
one block sits in one or two cache lines. Between events only two columns carry state:

    W[:, F0]  force on each block, c-free frame: F_i = (nu t - u_i - c) + l^2 (lap u)_i
    W[:, P]   psi_i = ln(theta_i)

both at the block's own time since[i] (lazy loading, see schedule.py).

All other columns are scratch that the event integrator leaves zeroed.

An event may run over several kernel calls (chain.simulate's work budget): the loop variables
of the event in progress stay in the vector `event` (EV_* below), and the undo log `undo` keeps
the between-events values (F0, P, since) of every block the event has changed so far, so that
`Workspace.between_events` can give the state before the event while it is paused.

Energy balance of an event (c-free frame, x = u + c - nu t, slips y since onset,
duration tau, W_f = int sum(Phi v) dt the friction work, W_load the work of the driver):

    dE_elastic - W_load = -sum(y F0) + sum(y^2)/2 + l^2 sum((dy)^2)/2
                          - nu tau sum(y) + nu int_0^tau sum(y) dt

so residual = dE_elastic + W_f - W_load needs only the blocks that slipped. Its scale
(D_ENERGY_SCALE) is the sum of the magnitudes of all these terms and of W_f: in the c-free frame
W_f alone can nearly cancel (b psi changes sign while a block slides), so it is no scale.
The terms are also kept apart, split where the force on a sliding block splits,
F0 + nu t - y + l^2 lap y: D_ELASTIC = -sum(y F0) + sum(y^2)/2 + l^2 sum((dy)^2)/2 is the
energy change from the slip with the driver held where it was at the onset, and
D_LOAD_WORK = nu tau sum(y) - nu int_0^tau sum(y) dt = nu int_0^tau t sum(v) dt the work of the
driver's advance since the onset on the sliding blocks; the rest of the two energy changes
(the driver alone pulling every block) cancels. residual = D_ELASTIC + D_WORK - D_LOAD_WORK.

A creep episode's row (kind 1) carries D_WORK, its blocks' friction work, and D_LOAD_WORK, the driver's
work on their slips since the episode's start, both accumulated step by step (E_WORK, E_LOAD_WORK,
creep._commit). Its elastic change is not its own (events and other episodes change its blocks' forces
while it runs), so D_ELASTIC, D_RESIDUAL and D_ENERGY_SCALE are NaN there: the balance closes over a
stretch of the run instead (ensemble/energy.py).
"""
from collections import namedtuple

import numpy as np

# Columns of W, one meaning each. "Step start" is the state a step (and its retries) starts from;
# "stage" the state at which a Runge-Kutta stage evaluates the rates.
Y = 0        # slip since the onset of the event (0 for a block that has not slid)
V = 1        # velocity (0 at rest)
P = 2        # state psi = ln(theta); between events at the block's time `since` (schedule.py)
TR = 3       # local time at which the block came to rest in this event (its state grows from there)
F0 = 4       # force at the onset of the event (between events: at time `since`), c-free frame
YS = 5       # stage slip (== Y for blocks at rest: neighbours read YS)
VS = 6       # stage velocity
PS = 7       # stage psi
Y0 = 8       # step start: slip
V0 = 9       # step start: velocity
P0 = 10      # step start: psi
KY = 11      # stage rate of the slip (the stage velocity)
KV = 12      # stage rate of the velocity (force minus friction)
KP = 13      # stage rate of psi (also the implicit solve's first guess from the previous stage)
SY = 14      # RK4: weighted sum of the stage rates of the slip
SV = 15      # RK4: ... of the velocity
SP = 16      # RK4: ... of psi
K1V = 17     # rate of the velocity at the step start (slope of the Hermite interpolant of v)
HD0 = 18     # h V0: slope of the slip's Hermite interpolant at the step start
HD1 = 19     # h V: ... at the step end
IM_TARGET = 20  # ARK implicit stage: lower bound of the root psi (laws/aging.py)
IM_RHS = 21     # ARK implicit stage: explicit part r of the stage equation
IM_EXP = 22     # ARK implicit stage: exp(-psi) of the solve's first guess
IM_UNSOLVED = 23  # ARK implicit stage: 1 where the two-step solve did not converge
# stage rates of the ARK steppers: ARK_STAGES columns each from ARK_V (dy/dt), ARK_A (dv/dt),
# ARK_G (dpsi/dt)
ARK_STAGES = 8
ARK_V = 24
ARK_A = ARK_V + ARK_STAGES
ARK_G = ARK_A + ARK_STAGES
TS = ARK_G + ARK_STAGES   # local time at which the block started to slide in this event (step trace)
LOGGED = TS + 1           # 1 while the block's between-events values are in the undo log (undo.py)
# the exponential integrator (exponential.py): theta = exp(psi) at the step start, and the step's
# coefficients of the state's exact linear part, functions of z = h r(v0) (laws: linear_state)
X_THETA0 = LOGGED + 1     # theta at the step start
X_RATE0 = X_THETA0 + 1    # r(v0): the rate of the linear part, frozen over the step
X_EH = X_RATE0 + 1        # exp(-z/2)
X_P1H = X_EH + 1          # phi_1(-z/2)
X_P2H = X_P1H + 1         # phi_2(-z/2)
X_P1 = X_P2H + 1          # phi_1(-z)
X_P2 = X_P1 + 1           # phi_2(-z)
X_P3 = X_P2 + 1           # phi_3(-z)
X_THETA = X_P3 + 1        # theta of the stage
NCOLS = X_THETA + 1

# entries of the per-event diagnostics vector
(D_DURATION, D_SLIP, D_FIRST, D_LAST, D_NSLIP, D_WORK, D_RESIDUAL, D_STEPS, D_VMAX,
 D_BLOCK_STEPS, D_REJECTED, D_CUTS, D_ENERGY_SCALE, D_ELASTIC, D_LOAD_WORK, D_KIND, D_ENDING,
 D_STRESS_DROP, D_N_ONSET, D_T_SPREAD, D_T_WIDEST, D_N_WIDEST, D_ACROSS_FIRST, D_ACROSS_LAST) = range(24)
NDIAG = 24
# D_FIRST, D_LAST: the lowest and highest position along strike of a block that slipped (geometry.along: on the
# chain its index); D_ACROSS_FIRST, D_ACROSS_LAST the same across strike (geometry.across: 0 on the chain)
# D_KIND: what a row of the kernels' output is; D_ENDING: how a creep episode ended (1 its blocks
# stopped, 2 an inertial event took them; 0 for an event)
# D_STRESS_DROP: an event's stress drop, the mean over the blocks that slipped (the set S) of the drop of
# their force (F0 + nu t - y + l^2 lap y) by the slip alone, the driver held where it was at the onset:
# (1 / |S|) sum_{i in S} y_i (1 + l^2 n_i), n_i the neighbours of i outside S (the springs within S cancel
# in the sum). The driver's advance adds nu * duration to every force (at most ~1e-5 at the paper's nu).
# NaN for a creep episode, whose blocks' slips are not kept one by one.
# The nucleation of an event (event.py; analysis/statistics/nucleation.py): D_N_ONSET the blocks sliding at its
# onset (1, or a creeping cluster handed over), D_T_SPREAD the local time at which a block beyond them started
# to slide (NaN: none did), D_N_WIDEST the most blocks sliding at once (the zone's widest: in a large event at
# b = 20 the crack-like growth of its nucleation, before the rupture splits into pulses of a few blocks) and
# D_T_WIDEST the local time it was first that wide; each at the end of a step. 0, NaN, 0, NaN for a creep episode.
KIND_EVENT, KIND_CREEP = 0, 1

# columns of the optional step trace of an event (one row per step tried, rejected ones included)
(T_TAU, T_H, T_SLIDING, T_ERROR, T_BLOCK, T_PART, T_AGE, T_V, T_PSI, T_OWN) = range(10)
NTRACE = 10
TRACE_COLUMNS = {
    T_TAU: "local time at the step start",
    T_H: "step size",
    T_SLIDING: "sliding blocks",
    T_ERROR: "error norm of the step (> 1: rejected, unless h fell below 1e-12; 0 for RK4)",
    T_BLOCK: "block with the largest error (-1 for RK4)",
    T_PART: "part of that block's error: 0 slip, 1 velocity, 2 state psi",
    T_AGE: "local time since that block started",
    T_V: "that block's velocity at the step end",
    T_PSI: "that block's psi at the step end",
    T_OWN: "block-steps had every block taken its own step: sum of min(1, max(0.1, (err_i / err)^(1/(q+1))))",
}

# Entries of the event-state vector `event` (float64; counts and block indices are exact in it).
# Between events only EV_PHASE (= BETWEEN) and EV_NUNDO (= 0) matter; during an event the
# others hold the event's loop variables while a kernel call is paused (event.continue_event).
EV_PHASE = 0        # BETWEEN, or IN_EVENT from the jump to the onset until the event has finished
EV_CLOCK_HI = 1     # the clock before the jump to this event's onset (two-float time, high part)
EV_CLOCK_LO = 2     # ... and its low part
EV_EPICENTER = 3    # the event's epicenter
EV_NA = 4           # number of sliding blocks (act[:na])
EV_NT = 5           # number of blocks that slid in this event (touched[:nt])
EV_YREST = 6        # sum of the slips of the blocks that slid and are at rest again
EV_T_FAR = 7        # local time of the earliest onset by loading alone of a block nobody watches
EV_FAR = 8          # that block (-1: none)
EV_TAU = 9          # local time since the onset
EV_WORK = 10        # friction work so far
EV_SLIP_TIME = 11   # time integral of the total slip so far
EV_STEPS = 12       # steps taken, rejected ones included (D_STEPS)
EV_BLOCK_STEPS = 13 # accepted block-steps (D_BLOCK_STEPS)
EV_REJECTED = 14    # rejected steps (D_REJECTED)
EV_CUTS = 15        # steps cut at a located transition (D_CUTS)
EV_VMAX = 16        # largest velocity so far (D_VMAX)
EV_H_NEXT = 17      # the next step size (adaptive methods; dt for RK4)
EV_ERR_PREV = 18    # error norm of the last accepted step (PI control)
EV_TRACED = 19      # rows of the step trace filled
EV_NUNDO = 20       # entries of the undo log
EV_STILL = 21       # steps in a row that left the event's time where it was (event.STALL_STEPS)
EV_N_ONSET = 22     # blocks sliding at the onset (D_N_ONSET)
EV_T_SPREAD = 23    # local time at which a block beyond them started (D_T_SPREAD; -1 until then)
EV_T_WIDEST = 24    # local time at which the most blocks were sliding at once (D_T_WIDEST)
EV_N_WIDEST = 25    # that many (D_N_WIDEST)
NEVENT = 26
# The loop variables of the event in progress (event.continue_event) as one record, saved into `event`
# when a kernel call pauses and restored from it at the next, field by field and by name: field `x` in
# slot EV_X (event._keep, event._resume). Built by keyword only, so the order of the fields below
# matters nowhere; a new loop variable is one field here, its slot above and a line in each of the two.
PausedEvent = namedtuple("PausedEvent", ["na", "nt", "yrest", "t_far", "far", "tau", "work", "slip_time", "steps",
                                         "block_steps", "rejected", "cuts", "vmax", "h_next", "err_prev", "traced",
                                         "still"])
# The creep phase (creep.py). Per block, the array `creep`: its first CR_KEEP columns are state
# (a checkpoint keeps them), the others scratch of one creep step.
CR_EP = 0       # 1 + the slot of the episode the block creeps in (0: not creeping)
CR_V = 1        # creep velocity at the last step's end
CR_SERIAL = 2   # serial number of the last episode that counted the block among its blocks
CR_KEEP = 3
CR_VN = 3       # the step's velocity (Newton's iterate); at an event's end the velocity handed back
CR_PSI = 4      # the step's psi at its end
CR_DPSI = 5     # d psi / d v of the step's state equation
CR_DU = 6       # the step's slip
CR_H = 7        # the block's own step (from its time since[i])
CR_RES = 8      # Newton's right-hand side; Thomas' forward sweep; the force at the step's end
CR_DIAG = 9     # Thomas' pivot
CR_UPPER = 10   # Newton's update of the block (read by its left neighbour in the back sweep)
CR_HB = 11      # 1: the event that just ended handed the block back to creep
CR_LEFT = 12    # 1: the block stopped creeping in the step being taken
CR_W = 13       # the block's weakening per unit slip (Law.creep_weakening) where a cluster's stability is checked
NCREEP = 14
# The episode table `episodes`: one row (slot) per episode running or ended and not yet reported
E_STATE = 0     # 0 free, E_RUNNING, E_STOPPED (its blocks stopped), E_RUPTURED (an event took them)
E_START_HI, E_START_LO = 1, 2      # two-float time at which it began
E_EPICENTER = 3                    # its first block
E_SLIP = 4                         # sum of its blocks' slips
E_FIRST, E_LAST = 5, 6             # lowest and highest position along strike that slipped in it
E_NBLOCKS = 7                      # blocks that crept in it
E_VMAX = 8                         # largest creep velocity
E_ACTIVE = 9                       # blocks creeping in it now
E_SERIAL = 10                      # its serial number (creep.join counts a block once per episode)
E_END_HI, E_END_LO = 11, 12        # two-float time at which it ended
E_BLOCK_STEPS = 13                 # creep steps of its blocks
E_WORK = 14        # friction work of its blocks' steps, c-free frame (creep._commit: trapezoidal in each step)
E_LOAD_WORK = 15   # the driver's work on its blocks' slips since its start: nu sum(du (t_mid - start)) (D_LOAD_WORK)
E_ACROSS_FIRST, E_ACROSS_LAST = 16, 17   # lowest and highest position across strike that slipped in it (E_FIRST,
                                         # E_LAST: along strike)
NEPISODE = 18
E_RUNNING, E_STOPPED, E_RUPTURED = 1.0, 2.0, 3.0
# The creep phase's own scalars `cstate`
CS_NCREEP = 0   # blocks creeping
CS_H = 1        # the next creep step
CS_SERIAL = 2   # episodes begun so far (serial numbers)
CS_ENDED = 3    # episodes ended and not yet reported
CS_T_HI, CS_T_LO = 4, 5   # two-float time up to which the creep is integrated
CS_FRESH = 6    # 1: blocks joined since the last step, the velocities are made consistent first
CS_DIRTY = 7    # 1: blocks joined or left since the list `crept` was made (Workspace.load sets it)
NCSTATE = 8

# Event histories (history.py): the control vector `hctl`, and the columns of a snapshot row of `history`
HC_ON = 0          # 1: continue_event takes snapshots of the event in progress
HC_SLIP_MIN = 1    # chain.simulate ends its call after an inertial event of at least this slip (HC_READY)
HC_DT = 2          # a snapshot at least this often in the event's local time
HC_RATIO = 3       # ... and whenever the largest velocity has changed by this factor
HC_COUNT = 4       # snapshots taken of the event in progress
HC_TAU = 5         # local time of the last snapshot
HC_V = 6           # largest velocity at the last snapshot
HC_DROPPED = 7     # snapshots dropped for want of rows (the buffer's last row keeps the end)
HC_READY = 8       # 1: the last row chain.simulate wrote is an event whose snapshots are in `history`
NHCTL = 9
H_TAU, H_LO, H_HI = 0, 1, 2    # a snapshot: local time since the onset, the touched blocks' span lo..hi,
H_NA = 3                       # the blocks sliding (a block started in the step is at rest at its end),
H_VALUES = 4                   # then the velocities of blocks 0..n-1 (valid on lo..hi), then their slips

# values of EV_PHASE
BETWEEN, IN_EVENT = 0, 1

# columns of the undo log: one row per block the event in progress has changed, in the order it
# first did, with the block's between-events values from before the event
U_BLOCK, U_F0, U_P, U_SINCE_HI, U_SINCE_LO = range(5)
NUNDO = 5

# values of `flag`: the block's part in the event in progress
UNTOUCHED = 0   # has not slid in this event (and between events: every block)
SLIDING = 1     # slides: in the active list act[:na]
STOPPED = 2     # slid in this event and is at rest again

# a work budget (chain.simulate, event.continue_event) that no run exhausts: integrate to the end
UNLIMITED = 2**62

# status codes of the kernels (all but OK and PAUSED are errors)
OK, NONFINITE, UNSTABLE, TOO_LONG, PAUSED, STALLED = 0, 1, 2, 3, 4, 5
STATUS_TEXT = {
    NONFINITE: "non-finite state or parameter (numerical blow-up, or NaN/inf in the input)",
    UNSTABLE: "step beyond the stability limit of RK4 (dt / theta > 2.785); reduce integrator.dt",
    TOO_LONG: "event exceeded integrator.max_duration (stable sliding? b below the block stiffness?)",
    PAUSED: "not an error: the work budget of the kernel call ran out in the middle of an event, "
            "which the next call continues",
    STALLED: "the steps stopped advancing time: a block's start or stop was located at the start of the step again "
             "and again (10000 steps at one time); rerun with another integrator.method",
}


# The work arrays as the kernels receive them: one record (chain.simulate, event.begin_event,
# continue_event, integrate_event), its fields read by name. n blocks; int is int64.
WorkArrays = namedtuple("WorkArrays", [
    "W",        # (n, NCOLS) float64: per-block quantities, the columns above
    "act",      # (n,) int: the sliding blocks, act[:na] (event.py)
    "flag",     # (n,) int8: UNTOUCHED, SLIDING or STOPPED (below), per block, in the event in progress
    "touched",  # (n,) int: the blocks that slid in this event, touched[:nt]
    "stuck",    # (n,) int: scratch of one step, the blocks that stopped in it
    "since",    # (n, 2) float64: two-float time at which a block's F0 and P hold between events (schedule.py)
    "tree",     # (tree_size(n),) float64: min-tree of the onset keys (schedule.py); NaN at the root: rebuild it
    "diag",     # (NDIAG,) float64: summary of the last event (D_*)
    "event",    # (NEVENT,) float64: the event in progress (EV_*)
    "undo",     # (n, NUNDO) float64: undo log of the event in progress (U_*, undo.py)
    "creep",    # (n, NCREEP) float64: per block, the creep phase (CR_*, creep.py)
    "episodes", # (2 n, NEPISODE) float64: creep episodes running or waiting to be reported (E_*)
    "cstate",   # (NCSTATE,) float64: the creep phase's scalars (CS_*)
    "crept",    # (n,) int: the creeping blocks in increasing order, crept[:cstate[CS_NCREEP]] (creep.py)
    "cluster",  # (n,) int: scratch, the blocks of one cluster (geometry.cluster)
    "seen",     # (n,) int8: scratch, 1 for the blocks a cluster walk has met (0 between the kernels' calls)
    "history",  # (snapshots, H_VALUES + 2 n) float64: the event's snapshots (history.py); 0 rows: none taken
    "hctl",     # (NHCTL,) float64: the histories' control (HC_*)
])


def tree_size(n):
    """Length of the onset tree (schedule.py) for n blocks: twice a power of two >= n."""
    m = 1
    while m < n:
        m *= 2
    return 2 * m


class Workspace:
    """Work arrays for one chain of n blocks (allocate once per task).

    Between events the state is lazy (see schedule.py): block i holds W[i, F0]
    and W[i, P] at the two-float time since[i]; `state` brings all of it to one time.
    """

    def __init__(self, n, snapshots=0):
        """snapshots: rows of the event-history buffer (history.py; 0: no histories)."""
        self.W = np.zeros((n, NCOLS))
        self.act = np.zeros(n, dtype=np.int64)
        self.flag = np.zeros(n, dtype=np.int8)
        self.touched = np.zeros(n, dtype=np.int64)
        self.stuck = np.zeros(n, dtype=np.int64)
        self.since = np.zeros((n, 2))
        self.tree = np.full(tree_size(n), np.nan)
        self.diag = np.zeros(NDIAG)
        self.event = np.zeros(NEVENT)
        self.undo = np.zeros((n, NUNDO))
        self.creep = np.zeros((n, NCREEP))
        self.episodes = np.zeros((2 * n, NEPISODE))
        self.cstate = np.zeros(NCSTATE)
        self.crept = np.zeros(n, dtype=np.int64)
        self.cluster = np.zeros(n, dtype=np.int64)
        self.seen = np.zeros(n, dtype=np.int8)
        self.history = np.zeros((snapshots, H_VALUES + 2 * n))
        self.hctl = np.zeros(NHCTL)

    @property
    def arrays(self):
        """The work arrays as the kernels take them (WorkArrays)."""
        return WorkArrays(W=self.W, act=self.act, flag=self.flag, touched=self.touched, stuck=self.stuck,
                          since=self.since, tree=self.tree, diag=self.diag, event=self.event, undo=self.undo,
                          creep=self.creep, episodes=self.episodes, cstate=self.cstate, crept=self.crept,
                          cluster=self.cluster, seen=self.seen,
                          history=self.history, hctl=self.hctl)

    def load(self, force, psi, since=None, creep=None):
        """Set the between-events state: force and psi of every block (at time since, default 0),
        and the creep phase's state (`creep_state`; default: nothing creeps).

        An event in progress is dropped.
        """
        self.W[:] = 0.0
        self.flag[:] = 0
        self.W[:, F0] = force
        self.W[:, P] = psi
        self.since[:] = 0.0 if since is None else since
        self.tree[:] = np.nan    # the kernels rebuild the schedule
        self.event[:] = 0.0      # BETWEEN, undo log empty
        self.hctl[HC_READY] = 0.0   # (no event of this state has snapshots)
        self.creep[:] = 0.0
        self.episodes[:] = 0.0
        self.cstate[:] = 0.0
        if creep is not None:
            n = self.creep.shape[0]
            k = n * CR_KEEP
            self.creep[:, :CR_KEEP] = creep[:k].reshape(n, CR_KEEP)
            self.episodes[:] = creep[k:k + self.episodes.size].reshape(self.episodes.shape)
            self.cstate[:] = creep[k + self.episodes.size:]
        self.cstate[CS_DIRTY] = 1.0

    @staticmethod
    def creep_size(n, episode_columns=NEPISODE):
        """Length of `creep_state` for n blocks (of an episode table of `episode_columns`: an older
        catalog's checkpoints kept fewer, store/schema.py: EPISODE_COLUMNS)."""
        return n * CR_KEEP + 2 * n * episode_columns + NCSTATE

    def creep_state(self):
        """The creep phase's state as one flat array (a copy), for a checkpoint: with the
        between-events state it continues the run exactly (`load`). An event in progress leaves it
        unchanged until the event's end (creep.after_event)."""
        return np.concatenate([self.creep[:, :CR_KEEP].ravel(), self.episodes.ravel(), self.cstate])

    def episodes_in_flight(self):
        """(start time, slip, friction work, loader's work) of each creep episode begun and not yet
        reported (running, or ended and waiting for its row): what it has done so far (energy.py)."""
        E = self.episodes[self.episodes[:, E_STATE] != 0.0]
        return (E[:, E_START_HI] + E[:, E_START_LO], E[:, E_SLIP].copy(), E[:, E_WORK].copy(),
                E[:, E_LOAD_WORK].copy())

    @property
    def paused(self):
        """True while an event is in progress (a kernel call stopped in its middle)."""
        return self.event[EV_PHASE] == IN_EVENT

    def between_events(self, clock):
        """(force, psi, since, clock): copies of the between-events state, exactly.

        Between events that is the current state and `clock`; during a paused event it is the
        state after the last completed event, as it was before the kernel jumped the clock to
        this event's onset and changed any block (from the undo log). The workspace is not
        changed. `Workspace.load(force, psi, since)` with that clock continues exactly as the
        uninterrupted run (the paused event is integrated again from its onset).
        """
        force, psi, since = self.W[:, F0].copy(), self.W[:, P].copy(), self.since.copy()
        clock = np.array(clock, dtype=float)
        if self.paused:
            log = self.undo[:int(self.event[EV_NUNDO])]
            who = log[:, U_BLOCK].astype(np.int64)      # each block once
            force[who] = log[:, U_F0]
            psi[who] = log[:, U_P]
            since[who, 0] = log[:, U_SINCE_HI]
            since[who, 1] = log[:, U_SINCE_LO]
            clock = self.event[[EV_CLOCK_HI, EV_CLOCK_LO]].copy()
        return force, psi, since, clock

    def state(self, clock, p):
        """(force, psi) of every block at the two-float time `clock` (new arrays); p, the
        kernels' parameters (params.KernelParams).

        During a paused event: of the between-events state before it (`between_events`).
        """
        from .laws import rest_states
        force, psi, since, _ = self.between_events(clock)
        dt = np.maximum((clock[0] - since[:, 0]) + (clock[1] - since[:, 1]), 0.0)
        return force + p.nu * dt, rest_states(p.law, psi, dt)

    @property
    def force(self):
        """Stored forces (each at its block's `since` time; see `state`)."""
        return self.W[:, F0]

    @property
    def psi(self):
        """Stored states psi (each at its block's `since` time; see `state`)."""
        return self.W[:, P]
