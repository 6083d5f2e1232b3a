"""Hard cases run without tuning and without non-finite values; energy balance holds (small sizes).

Every case runs with fixed-step RK4 (the paper's method, which needs its step chosen per case:
b = 100 slips at v ~ 7000, beyond RK4's stability limit dt * v < 2.785 at dt = 1e-3, so it
runs at dt = 2e-4) and with each adaptive method at its default tolerances and no per-case
tuning. The full sizes (N = 800, 6400) are benchmarks/hard_cases.py.

The two c cases cannot fail for a kernel bug that the other cases would not show: c never
reaches the kernels (the c-free frame removes it exactly; kernel_params does not pass it, and the
initial state does not depend on it), so "c = 1e2" and "c = 1e6" run bit-identical events (as
the printed numbers show). They stay as a guard that c keeps out of the kernels; the kernel's
physics with c is checked against references that keep c (test_physics.py, test_sequences.py).
"""
import numpy as np
import pytest

from ensemble.store.checkpoint import Checkpoint
from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import relative_energy_residual
from ensemble.model.workspace import D_ENERGY_SCALE, D_RESIDUAL, D_SLIP, D_T_SPREAD, D_VMAX
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list

# adaptive methods, run at Integrator()'s defaults (a new one is one word here)
ADAPTIVE = ["ark3", "ark4", "exp4"]
METHODS = ["rk4", *ADAPTIVE]

# name: (model, RK4 step, events recorded after as many transient events)
CASES = {
    "very fast slip b = 100": (Model(N=100, b=100.0), 2e-4, 40),
    "strong strengthening a = 30": (Model(N=60, a=30.0), 1e-3, 8),
    "c = 1e2": (Model(N=100, c=1e2), 1e-3, 40),    # identical events: c never reaches the kernel
    "c = 1e6": (Model(N=100, c=1e6), 1e-3, 40),
    "nu = 1e-6": (Model(N=100, nu=1e-6), 1e-3, 40),
    "nu = 1e-10": (Model(N=100, nu=1e-10), 1e-3, 40),
    "N = 6400": (Model(N=6400), 1e-3, 6),
}


def integrator(method, rk4_dt=1e-3):
    """RK4 at the step the case needs; an adaptive method exactly at its defaults."""
    return Integrator(method="rk4", dt=rk4_dt) if method == "rk4" else Integrator(method=method)


def residual_bounds(method):
    """(max, median) relative energy residual over a case's events.

    RK4 at these steps conserves energy to round-off: measured max 4.8e-12 (a = 30; 5.1e-12 in
    the slow run past 1e16), largest median 3.5e-12. An adaptive method follows its tolerance:
    largest median measured 0.077 rtol (ark4, N = 6400), largest max 0.26 rtol here (ark3,
    b = 100; 0.15 rtol in the slow run), with rare outliers elsewhere where the friction work
    is a small difference of large terms (2.5e-4 = 250 rtol once in 2800 events at N = 100,
    benchmarks/hard_cases.py): hence the max bound 1000 rtol, and the median bound 1 rtol,
    which is what sees a systematic error.
    """
    if method == "rk4":
        return 1e-10, 1e-10
    rtol = Integrator().rtol
    return 1000 * rtol, rtol


def trajectory(model, integ):
    cfg = Config(model=model, run=Run(), integrator=integ)
    return Trajectory(cfg, task_list(cfg)[0])


def check_events(label, method, t, diag):
    """Finite, strictly increasing onsets, every event slipped, energy balance; prints the numbers."""
    # (the initial phase's end is NaN for an event whose sliding zone never grew beyond its onset's)
    finite = np.isfinite(np.delete(diag, D_T_SPREAD, axis=1))
    assert np.all(finite) and np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)
    assert np.all(diag[:, D_SLIP] > 0)
    residual = relative_energy_residual(diag[:, D_RESIDUAL], diag[:, D_ENERGY_SCALE])
    mu = np.log10(diag[:, D_SLIP])
    print(f"{label} [{method}]: relative energy residual max {residual.max():.1e} median "
          f"{np.median(residual):.1e}, v_max {diag[:, D_VMAX].max():.0f}, mu {mu.min():.2f}..{mu.max():.2f}, "
          f"t_end {t[-1]:.2e}")
    bound_max, bound_median = residual_bounds(method)
    assert residual.max() < bound_max and np.median(residual) < bound_median


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", CASES)
def test_hard_case(name, method):
    model, rk4_dt, events = CASES[name]
    traj = trajectory(model, integrator(method, rk4_dt))
    traj.advance(events)
    t, _, diag = traj.advance(events)
    check_events(name, method, t, diag)


def run_past(traj, t_end, chunk=20):
    """Advance in chunks until the clock passes t_end; (onset times, diagnostics) of all events."""
    ts, diags = [], []
    while traj.clock[0] + traj.clock[1] <= t_end:
        t, _, diag = traj.advance(chunk)
        ts.append(t)
        diags.append(diag)
    return np.concatenate(ts), np.concatenate(diags)


def check_long_run(method, N, t_end, compare=5):
    """A genuine run past t_end, then the same run restarted with its clock reset to 0.

    Both continue from the same physical state (the restart has it brought to one time, which
    changes round-off only), so their first events agree up to chaotic growth of round-off:
    measured at most 9e-15 past 1e15 (every method), 7e-6 past 1e16 (ark4 at its default rtol 1e-4,
    2026-11-29; an earlier measurement gave 1e-8 for ark3). A dependence on the absolute time (e.g. a
    time since rest of ~1e-3 taken as a difference of two times near 1e15 in single float64, resolution
    0.125) would show here as errors of order 1.
    """
    model = Model(N=N, nu=1e-10)        # ~ 5e12 time units per event: 1e15 after ~200 events
    traj = trajectory(model, integrator(method))
    t, diag = run_past(traj, t_end)
    check_events(f"long run N = {N}, {len(t)} events", method, t, diag)
    start = traj.clock.copy()
    force, psi = traj.state()
    cfg = traj.cfg
    fresh = Trajectory(cfg, traj.task, Checkpoint(force, psi, np.zeros((N, 2)), np.zeros(2), traj.done))
    t_late, epi_late, diag_late = traj.advance(compare)
    t_reset, epi_reset, diag_reset = fresh.advance(compare)
    check_events(f"after {start.sum():.1e}", method, t_late, diag_late)
    since_start = (t_late - start[0]) - start[1]
    rel_t = np.abs(since_start - t_reset) / t_reset
    rel_slip = np.abs(diag_late[:, D_SLIP] - diag_reset[:, D_SLIP]) / diag_late[:, D_SLIP]
    print(f"  restart with the clock at 0: relative differences of the next {compare} events: onset "
          f"{np.array2string(rel_t, precision=0)}, slip {np.array2string(rel_slip, precision=0)}")
    np.testing.assert_array_equal(epi_late, epi_reset)
    # A dependence on the absolute time would show as differences of order 1; what remains is
    # round-off of the restarted state, amplified by the chaotic dynamics (more so with adaptive
    # steps, whose sequence changes discretely, and the more the looser their tolerance): measured
    # at most 7e-6 (ark4 at its default rtol 1e-4, past 1e16, the fifth event; 2026-11-29, the same
    # before and after the kernels were compiled once per law), bound 10x that, 1e4 below order 1.
    assert rel_t.max() < 1e-4 and rel_slip.max() < 1e-4


@pytest.mark.parametrize("method", METHODS)
def test_run_past_1e15(method):
    """N = 20, nu = 1e-10: the clock passes 1e15 after ~190 events (a few seconds)."""
    check_long_run(method, 20, 1e15)


@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
def test_run_past_1e16(method):
    """N = 100, nu = 1e-10 to t > 1e16: ~2700 events (rk4 ~0.5 min, ark3 ~1.5 min)."""
    check_long_run(method, 100, 1e16)


@pytest.mark.parametrize("method", METHODS)
def test_nucleation_below_float_resolution_of_the_threshold(method):
    """nu = 1e-10 with a first step of 2e-4: every event must slip.

    The epicenter's force then grows by nu * dt = 2e-14 per step, below the rounding of its
    threshold b psi ~ 535 (1.1e-13): the kernel used to declare it stuck at once and record
    an event with zero slip, forever (the block keeps sliding at v = 0 until it moves now).
    """
    traj = trajectory(Model(N=20, nu=1e-10), Integrator(method=method, dt=2e-4))
    _, _, diag = traj.advance(20)
    assert np.all(diag[:, D_SLIP] > 0)
