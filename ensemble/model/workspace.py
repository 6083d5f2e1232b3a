"""Work arrays shared by the event kernels, and the codes they return.

The float work array W has one row per block and one column per per-block
quantity (index constants below), so that everything the integrator touches for
one block sits in one or two cache lines. Between events only two columns carry state:

    W[:, F0]  force on each block, c-free frame: F_i = (nu t - u_i - c) + l^2 (lap u)_i
    W[:, P]   psi_i = ln(theta_i)

both at the block's own time since[i] (lazy loading, see schedule.py).

All other columns are scratch that the event integrator leaves zeroed.

Energy balance of an event (c-free frame, x = u + c - nu t, slips y since onset,
duration tau, W_f = int sum(Phi v) dt the friction work, W_load the work of the driver):

    dE_elastic - W_load = -sum(y F0) + sum(y^2)/2 + l^2 sum((dy)^2)/2
                          - nu tau sum(y) + nu int_0^tau sum(y) dt

so residual = dE_elastic + W_f - W_load needs only the blocks that slipped. Its scale
(D_ENERGY_SCALE) is the sum of the magnitudes of all these terms and of W_f: in the c-free frame
W_f alone can nearly cancel (b psi changes sign while a block slides), so it is no scale.
"""
import numpy as np

# columns of W
Y, V, P, TR, F0, YS, VS, PS, Y0, V0, P0, KY, KV, KP, SY, SV, SP, K1V, HD0, HD1 = range(20)
# stage derivatives of the ARK steppers: ARK_STAGES columns each from ARK_V (dy/dt), ARK_A (dv/dt),
# ARK_G (dpsi/dt)
ARK_STAGES = 8
ARK_V = 20
ARK_A = ARK_V + ARK_STAGES
ARK_G = ARK_A + ARK_STAGES
# local time at which a block started to slide in this event (for the step trace)
TS = ARK_G + ARK_STAGES
NCOLS = TS + 1

# entries of the per-event diagnostics vector
(D_DURATION, D_SLIP, D_FIRST, D_LAST, D_NSLIP, D_WORK, D_RESIDUAL, D_STEPS, D_VMAX,
 D_BLOCK_STEPS, D_REJECTED, D_CUTS, D_ENERGY_SCALE) = range(13)
NDIAG = 13

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

# status codes of the kernels
OK, NONFINITE, UNSTABLE, TOO_LONG = 0, 1, 2, 3
STATUS_TEXT = {
    NONFINITE: "non-finite state (numerical blow-up)",
    UNSTABLE: "step beyond the stability limit of RK4 (dt / theta > 2.785); reduce integrator.dt",
    TOO_LONG: "event exceeded integrator.max_duration (stable sliding? b below the block stiffness?)",
}


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

    def __init__(self, n):
        self.W = np.zeros((n, NCOLS))
        self.act = np.zeros(n, dtype=np.int64)
        self.flag = np.zeros(n, dtype=np.int8)
        self.touched = np.zeros(n, dtype=np.int64)
        self.stuck = np.zeros(n, dtype=np.int64)
        self.since = np.zeros((n, 2))
        self.tree = np.full(tree_size(n), np.nan)
        self.diag = np.zeros(NDIAG)

    @property
    def arrays(self):
        """The kernels' leading array arguments: W, act, flag, touched, stuck, since, tree, diag."""
        return self.W, self.act, self.flag, self.touched, self.stuck, self.since, self.tree, self.diag

    def load(self, force, psi, since=None):
        """Set the between-events state: force and psi of every block (at time since, default 0)."""
        self.W[:] = 0.0
        self.flag[:] = 0
        self.W[:, F0] = force
        self.W[:, P] = psi
        self.since[:] = 0.0 if since is None else since
        self.tree[:] = np.nan    # the kernels rebuild the schedule

    def state(self, clock, nu):
        """(force, psi) of every block at the two-float time `clock` (new arrays)."""
        dt = np.maximum((clock[0] - self.since[:, 0]) + (clock[1] - self.since[:, 1]), 0.0)
        psi = self.W[:, P]
        return self.W[:, F0] + nu * dt, psi + np.log1p(dt * np.exp(-psi))

    @property
    def force(self):
        """Stored forces (each at its block's `since` time; see `state`)."""
        return self.W[:, F0]

    @property
    def psi(self):
        """Stored states psi (each at its block's `since` time; see `state`)."""
        return self.W[:, P]
