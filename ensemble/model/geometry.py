"""The chain's geometry and the spring force on one block (the friction laws are in laws/).

Frame: forces without constant friction (the aging law's c is removed exactly by the shift
w = u + c), so a block's force is compared with its law's threshold (laws/__init__.py).
"""
import numba as nb

# The smallest eigenvalue of the chain's stiffness operator (the loader's spring 1 on every block, l^2 between
# neighbours, free ends): every block moving together stretches only the loader's springs. No cluster of creeping
# blocks is softer, so a law whose steady creep weakens by at most this never turns unstable (laws: steady_weakening).
SOFTEST_STIFFNESS = 1.0


@nb.njit(cache=True, inline="always")
def left(i):
    """Left neighbour of block i; at the free end the block itself (ghost u_{-1} = u_0)."""
    return i - 1 if i > 0 else i


@nb.njit(cache=True, inline="always")
def right(i, n):
    """Right neighbour of block i in a chain of n; at the free end the block itself."""
    return i + 1 if i < n - 1 else i


@nb.njit(cache=True, inline="always")
def spring_force(F0, tau, nu, l2, y_left, y_mid, y_right):
    """Force on a block at local time tau after the event started.

    F0 is the block's force at the start of the event (c-free frame), y_* the
    slips since the start of the event of the block and its two neighbours
    (at a free end the missing neighbour is the block itself).
    """
    return F0 + nu * tau - y_mid + l2 * (y_right - 2.0 * y_mid + y_left)
