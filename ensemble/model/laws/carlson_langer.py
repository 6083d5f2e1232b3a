"""Velocity-weakening friction of Carlson & Langer, as Mori & Kawamura used it for the BK chain.

    Phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma))   for v > 0,   static threshold 1 at rest

(Carlson & Langer, PRL 62, 2632, 1989; Mori & Kawamura, PRL 94, 058501, 2005 and JGR 111,
B07302, 2006). Friction drops from the threshold 1 to 1 - sigma as a block starts, then weakens
with slope 2 alpha at v = 0+. There is no state variable (psi stays 0, no state stages).

The loader stands still during an event (the zero-loading-velocity limit of Carlson, Langer, Shaw
& Tang, PRA 44, 884, 1991): nu sets only the loading between events, and an event takes no
loading time, so the clock does not advance during it (an event's duration is still recorded).
With the loader moving at a nu near the literature's, blocks reach their threshold by loading
while a long event lasts and events at N = 800 would never end.
"""
import math
from collections import namedtuple

import numba as nb

from . import Key, Law, Scales

CarlsonLangerParams = namedtuple("CarlsonLangerParams", "alpha sigma")


@nb.njit(cache=True, inline="always")
def friction(law, v, psi):
    """(1 - sigma) / (1 + 2 alpha v / (1 - sigma)) at max(v, 0) (a Runge-Kutta stage can see v < 0)."""
    vp = v if v > 0.0 else 0.0
    s = 1.0 - law.sigma
    return s / (1.0 + 2.0 * law.alpha * vp / s)


@nb.njit(cache=True, inline="always")
def threshold(law, psi):
    return 1.0


@nb.njit(cache=True, inline="always")
def state_rate(law, v, psi):
    return 0.0


@nb.njit(cache=True, inline="always")
def rest_state(law, psi, dt):
    return psi


@nb.njit(cache=True, inline="always")
def onset_delay(law, force, psi, nu):
    """The loader alone raises the force linearly to the threshold 1."""
    if force >= 1.0:
        return 0.0
    return (1.0 - force) / nu


@nb.njit(cache=True, inline="always")
def implicit_state(law, W, act, na, hg):
    """No state: nothing is stiff (never called; the kernels skip state stages)."""


@nb.njit(cache=True, inline="always")
def stiff_limit(law, rate_limit):
    return -math.inf


@nb.njit(cache=True, inline="always")
def rk4_unstable(law, v, psi, rate_limit, state_limit):
    """Nothing stiff: the weakening slope makes slow sliding grow, which is the physics."""
    return False


LAW = Law(
    name="carlson-langer",
    params=CarlsonLangerParams,
    keys={
        "alpha": Key(2.0, "model time / model length", lambda x: x >= 0, ">= 0",
                     "velocity weakening: friction slope -2 alpha at v = 0+"),
        "sigma": Key(0.01, "model force", lambda x: 0 < x < 1, "in (0, 1)",
                     "drop of friction from the static 1 to 1 - sigma as a block starts"),
    },
    convention="velocity-weakening friction (1 - sigma) / (1 + 2 alpha v / (1 - sigma)) while sliding, static "
               "threshold 1 at rest, no state (Carlson & Langer 1989; Mori & Kawamura 2005, 2006); the loader "
               "stands still during events (Carlson, Langer, Shaw & Tang 1991): events take no loading time",
    has_state=False, loader_moves=False,
    friction=friction, threshold=threshold, state_rate=state_rate, rest_state=rest_state,
    onset_delay=onset_delay, implicit_state=implicit_state, stiff_limit=stiff_limit,
    rk4_unstable=rk4_unstable,
    # at sigma = 0.01 and alpha = 1..3 (examples/laws/carlson_langer.toml): one-block events at
    # mu = -2.8..-1.3, events slipping 50 blocks or more at mu >= 0.7..1.2 (99%), T nu of order 1
    scales=Scales(mu_bins="-3:3:60", mu_c=1.0, b_cut=-1.0, tnu_bins="0:4:80"))
