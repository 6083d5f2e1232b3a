"""The step's interpolant of an event's slips (transitions.py locates sticks and onsets on it; a geometry's
spring_force_at reads the neighbours' slips from it)."""
import numba as nb

from .workspace import HD0, HD1, SLIDING, Y, Y0


@nb.njit(cache=True, inline="always")
def hermite(x, y0, y1, d0, d1):
    """Cubic Hermite on [0, 1] with end values y0, y1 and end slopes d0, d1 (per unit x)."""
    x2 = x * x
    x3 = x2 * x
    return ((2 * x3 - 3 * x2 + 1) * y0 + (x3 - 2 * x2 + x) * d0
            + (3 * x2 - 2 * x3) * y1 + (x3 - x2) * d1)


@nb.njit(cache=True, inline="always")
def slip_at(W, flag, j, x):
    """Slip of block j at fraction x of the current step (Hermite if it slides)."""
    if flag[j] != SLIDING:
        return W[j, Y]
    return hermite(x, W[j, Y0], W[j, Y], W[j, HD0], W[j, HD1])
