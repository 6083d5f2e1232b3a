"""Step-size control of the event loop (event.continue_event): accepting a step, and the size of the next.

The method (methods.py) takes a step of the sliding blocks from the step start; an adaptive one
retries it shorter until its error norm is at most 1, then a PI controller sizes the next step.
RK4 takes every step at once, at its fixed dt. Each try may fill a row of the step trace (`record`).
"""
import numba as nb

from .methods import adaptive, error_weights
from .steppers import block_error
from .workspace import P, T_AGE, T_BLOCK, T_ERROR, T_H, T_OWN, T_PART, T_PSI, T_SLIDING, T_TAU, T_V, TS, V

# PI control of the accepted steps (Gustafsson; Hairer & Wanner II, sec. IV.2): the next step is
# h 0.9 err^(-0.7/(q+1)) err_prev^(0.4/(q+1)), err_prev the last accepted step's error, -1/(q+1) the
# method's control exponent (methods.py). Against the plain 0.9 err^(-1/(q+1)) it rejects fewer
# steps at equal slip error (docs/numerics.md; benchmarks/step_budget.py measures it).
_PI_I, _PI_P = 0.7, 0.4


@nb.njit(cache=True, inline="always")
def accepted(p, err, h):
    """The step tried (size h, error norm err) is accepted: always for RK4, for an adaptive method
    once its error is at most 1 (or the step has shrunk to nothing)."""
    return not adaptive(p.method) or err <= 1.0 or h < 1e-12


@nb.njit(cache=True, inline="always")
def retry_size(p, h, err):
    """The size of the retry of a rejected step of size h and error norm err."""
    return h * max(0.2, 0.9 * err ** p.method.control_exponent)


@nb.njit(cache=True, inline="always")
def next_step_size(p, h, err, err_prev, retried, h_next):
    """(the next step's size, err_prev) after a step of size h accepted with error norm err: the PI
    controller for an adaptive method; RK4 keeps its step."""
    if not adaptive(p.method):
        return h_next, err_prev
    expo = p.method.control_exponent
    if err == 0.0:
        grow = 5.0
    else:
        grow = min(5.0, max(0.2, 0.9 * err ** (_PI_I * expo) * max(err_prev, 1e-4) ** (-_PI_P * expo)))
    if retried:
        # no growth right after a rejection (the step just failed at a larger h): fewer steps and
        # fewer rejections on large events
        grow = min(grow, 1.0)
    return min(p.max_step, h * grow), err


@nb.njit(cache=True)
def record(trace, row, p, W, act, na, tau, h, err):
    """Row `row` of the step trace (workspace.TRACE_COLUMNS) for the step just tried."""
    trace[row, T_TAU] = tau
    trace[row, T_H] = h
    trace[row, T_SLIDING] = na
    trace[row, T_ERROR] = err
    trace[row, T_BLOCK] = -1
    if not adaptive(p.method):
        return
    # a block whose error is e could have taken a step (err / e)^(1/(q+1)) times longer (counted
    # as at most 10x: a block with a vanishing error estimate still has to step)
    expo = p.method.control_exponent
    own = 0.0
    worst = -1.0
    for k in range(na):
        i = act[k]
        parts = block_error(W, i, h, p.rtol, p.atol, error_weights(p.method))
        e = max(parts)
        own += 1.0 if err <= 0.0 else min(1.0, max(0.1, (e / err) ** -expo))
        if e > worst:
            worst = e
            trace[row, T_BLOCK] = i
            trace[row, T_PART] = 0 if e == parts[0] else (1 if e == parts[1] else 2)
            trace[row, T_AGE] = tau + h - W[i, TS]
            trace[row, T_V] = W[i, V]
            trace[row, T_PSI] = W[i, P]
    trace[row, T_OWN] = own
