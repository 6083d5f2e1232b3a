"""Quiet loading between events: when does a block at rest start to slide?

All quantities are dimensionless and in the frame where c is removed (w = u + c),
so the static threshold of block i is b * psi_i with psi_i = ln(theta_i).

While every block is at rest, block i feels the force F_i(t) = F_i + nu * dt
(the driver moves, nothing else does) and its state grows as theta_i + dt.
It starts to slide when

    F_i + nu * dt = b * ln(theta_i + dt).

With z = theta_i + dt and y = nu * z / b this is y - ln y = L with
L = ln(b / nu) - (F_i - nu * theta_i) / b, whose root on the branch y >= 1
(the force overtakes the slowly growing threshold there) is the onset.
Everything is done with psi (not theta) so no intermediate overflows.
"""
import math

import numba as nb

# Newton on y - ln y = L converges from above in a handful of steps; this is a
# hard cap against pathological input (NaN), not an expected iteration count.
_MAX_NEWTON = 100


@nb.njit(cache=True)
def solve_y_minus_log_y(L):
    """Root y >= 1 of y - ln(y) = L for L >= 1 (the W_{-1} branch of Lambert W).

    Newton from a starting point above the root: the function is convex and
    increasing for y > 1, so the iterates decrease monotonically onto the root
    and never undershoot it (the onset is never reported early).
    """
    if not (L > 1.0):
        return 1.0
    d = L - 1.0
    # Both guesses lie above the root: 2L because L - ln(2L) > 0 for all L >= 1,
    # 1 + sqrt(2d) + d because e - ln(1 + e) < e^2 / 2 for e > 0.
    y = min(2.0 * L, 1.0 + math.sqrt(2.0 * d) + d)
    for _ in range(_MAX_NEWTON):
        f = y - math.log(y) - L
        step = f / (1.0 - 1.0 / y)
        y_new = y - step
        if y_new < 1.0:
            y_new = 1.0
        if y_new >= y or y - y_new <= 4e-16 * y:
            return y_new
        y = y_new
    return y


@nb.njit(cache=True)
def onset_delay(F, psi, nu, b):
    """Time until a block at rest with force F and state psi = ln(theta) slides.

    F is the force in the c-free frame; the block slides once F + nu*dt exceeds
    b * ln(theta + dt). Returns 0 when the block is already at (or, by round-off,
    above) its threshold. Requires nu > 0 and b > 0.
    """
    if F >= b * psi:
        return 0.0
    # L = ln(b/nu) - F/b + nu*theta/b, written with psi so nothing overflows:
    # nu*theta/b = exp(psi + ln(nu/b)). ln(b/nu) from the two logarithms only where the ratio
    # itself overflows or underflows (b = 1e300, nu = 1e-20), which would make L NaN; the one
    # rounding of the ratio elsewhere keeps every onset as it was.
    ratio = b / nu
    if 0.0 < ratio < math.inf:
        log_b_over_nu = math.log(ratio)
    else:
        log_b_over_nu = math.log(b) - math.log(nu)
    y_theta = math.exp(psi - log_b_over_nu)  # nu * theta / b
    L = log_b_over_nu - F / b + y_theta
    y = solve_y_minus_log_y(L)
    if y <= y_theta:
        return 0.0
    return (y - y_theta) * (b / nu)


@nb.njit(cache=True)
def grow_state(psi, dt):
    """psi after dt at rest: ln(theta + dt), computed as psi + log1p(dt / theta)."""
    return psi + math.log1p(dt * math.exp(-psi))
