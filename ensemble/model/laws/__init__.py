"""Friction laws: the registry, and the calls through which the kernels use a law.

A law is one module of this package that defines `LAW`, a `Law` record (below). Nothing else
in the kernels knows which law runs: they call the functions of this module (`friction`,
`threshold`, `state_rate`, ...), each taking the law's parameter record as its first argument.
That record is a namedtuple of the law's own class (aging.AgingParams, ...), so numba compiles
the kernels once per law, and each call here resolves, at compile time, to the law's own
function (numba.extending.overload, inlined): no branch on the law at run time.

Frame and units: dimensionless, forces without any constant friction (aging's c is removed by a
shift of u), so a block at rest with force F and state psi starts to slide once
F >= threshold(law, psi). A law without a state variable ignores psi (the kernels keep it 0).

Adding a law: docs/laws.md, section "Adding a friction law".
"""
import importlib
import math
import pkgutil
from dataclasses import dataclass

import numba as nb
import numpy as np
from numba.extending import overload


@dataclass(frozen=True)
class Key:
    """A [model] key that belongs to a law."""
    default: float
    unit: str           # as the catalog names units (catalog.DATASETS): "model force", "1", ...
    check: object       # value -> bool
    rule: str           # what check requires, for the error message ("> 0")
    meaning: str        # one line, for the docs and `validate`


@dataclass(frozen=True)
class Scales:
    """Where a law's statistics lie: the defaults of `analysis reduce` for catalogs of this law
    (its magnitudes log10(total slip) and loader displacements T nu have the law's own scale)."""
    mu_bins: str          # magnitude bins lo:hi:n of R(mu)
    mu_c: float           # large events: mu >= mu_c (recurrence times, fraction of large events)
    b_cut: float          # the Gutenberg-Richter fit above this magnitude
    tnu_bins: str         # bins lo:hi:n of the local recurrence times T nu


@dataclass(frozen=True)
class Law:
    """What a friction law supplies. Every function is numba-compiled and takes the law's
    parameter record (`params`) first; see the module's docstring for the frame."""
    name: str             # the value of model.law
    params: type          # namedtuple class of the parameters the kernels read (a subset of keys)
    keys: dict            # [model] keys of the law: name -> Key, in the order the config writes them
    convention: str       # one paragraph: the law and its conventions (stored in every catalog)
    has_state: bool       # integrate a state psi while sliding (False: psi stays 0, no state stages)
    loader_moves: bool    # the loader advances at nu during events (False: it stands still during
                          # an event and the clock with it; events take no loading time)
    friction: object      # (law, v, psi) -> dynamic friction while sliding, at max(v, 0)
    threshold: object     # (law, psi) -> static threshold of a block at rest
    state_rate: object    # (law, v, psi) -> d psi / dt while sliding (has_state)
    rest_state: object    # (law, psi, dt) -> psi after dt at rest
    onset_delay: object   # (law, F, psi, nu) -> time at rest until F + nu t reaches the threshold
    implicit_state: object  # (law, W, act, na, hg): the stiff state's implicit stage (steppers.py)
    stiff_limit: object   # (law, rate_limit) -> the state bound beyond which RK4 is unstable
    rk4_unstable: object  # (law, v, psi, rate_limit, state_limit) -> RK4's step left its stability region
    scales: Scales        # the reduction's defaults for this law's magnitudes and recurrence times
    method: str = "ark4"  # integrator.method of a config that does not set it: the fastest method whose
                          # statistics are those of the tight reference for this law (docs/benchmarks.md)
    linear_state: object = None  # (law, v) -> (s, r): the state's equation is linear in theta = exp(psi),
                          # theta' = s - r theta while sliding, with s and r functions of v alone (the
                          # exponential integrator, model/exponential.py, solves it exactly over a step);
                          # None: not of this form, and a law with a state then refuses that method
    # Quasi-static creep (model/creep.py, docs/numerics.md "Quasi-static creep"); a law without
    # `creep_state` never creeps (a block that reaches its threshold always starts an event)
    creep_weakening: object = None  # (law, v, psi) -> w = -d friction / d slip of a block creeping at v
                          # with state psi, -(d friction / d psi) (d psi' / d v); a cluster may creep
                          # while K_C - diag(w) is positive definite (K_C its stiffness matrix); the
                          # aging law: b at every state
    creep_state: object = None  # (law, psi0, v, h) -> (psi, d psi / d v): the state after a backward
                          # Euler step of size h at velocity v from psi0
    friction_slopes: object = None  # (law, v, psi) -> (d friction / d v, d friction / d psi)
    steady_weakening: str = ""  # the [model] key whose value is the weakening of a block creeping steadily at
                          # a small v (-d friction / d slip at the steady state; aging and slip: b): a chain
                          # whose softest stiffness (geometry.SOFTEST_STIFFNESS) is above that creeps steadily
                          # for ever and never has an event, so config.py refuses it; "": no creep

    @property
    def creeps(self):
        return self.creep_state is not None

    def kernel_params(self, model):
        """The law's parameter record for the kernels from a config's model section."""
        return self.params(**{name: float(getattr(model, name)) for name in self.params._fields})


def _discover():
    laws = {}
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        law = getattr(module, "LAW", None)
        if isinstance(law, Law):
            if law.name in laws:
                raise RuntimeError(f"two friction laws named {law.name!r}")
            laws[law.name] = law
    return laws


LAWS = _discover()              # model.law -> Law
DEFAULT = "aging"
_BY_PARAMS = {law.params: law for law in LAWS.values()}


def get(name):
    return LAWS[name]


# The kernels' calls. Each is a stub that numba replaces by the law's function.

def friction(law, v, psi):
    """Dynamic friction of a sliding block at velocity max(v, 0) and state psi."""


def threshold(law, psi):
    """Static threshold of a block at rest with state psi."""


def state_rate(law, v, psi):
    """d psi / dt of a sliding block."""


def rest_state(law, psi, dt):
    """psi of a block after dt at rest."""


def onset_delay(law, force, psi, nu):
    """Time until a block at rest (force, psi) loaded at rate nu reaches its threshold (0 if it has)."""


def implicit_state(law, W, act, na, hg):
    """The implicit stage of the state of the active blocks (steppers.ark_step)."""


def linear_state(law, v):
    """(s, r) of the state's equation theta' = s - r theta, theta = exp(psi), at velocity v (Law.linear_state)."""


def creeps(law):
    """The law has a quasi-static creep phase (a compile-time constant)."""


def creep_weakening(law, v, psi):
    """w at (v, psi): a cluster may creep while its stiffness matrix minus diag(w) is positive definite."""


def creep_state(law, psi0, v, h):
    """(psi, d psi / d v) after a backward-Euler step h of the state at velocity v from psi0."""


def friction_slopes(law, v, psi):
    """(d friction / d v, d friction / d psi) of a sliding block."""


def stiff_limit(law, rate_limit):
    """The state bound of RK4's stability for a step with rate_limit = RK4_STABILITY / dt."""


def rk4_unstable(law, v, psi, rate_limit, state_limit):
    """A block's stiff part beyond RK4's stability region."""


def has_state(law):
    """The law integrates a state while sliding (a compile-time constant)."""


def loader_moves(law):
    """The loader advances during events (a compile-time constant)."""


def _dispatch(stub, field):
    """Compile calls of `stub` to the law's own function `field` (chosen by the record's type).

    numba inlines neither *args nor closures over them, so each arity has its own impl.
    """
    def choose(law):
        return getattr(_BY_PARAMS[law.instance_class], field)

    arity = stub.__code__.co_argcount - 1
    if arity == 2:
        @overload(stub, inline="always")
        def _two(law, x, y):
            fn = choose(law)
            return lambda law, x, y: fn(law, x, y)
    elif arity == 3:
        @overload(stub, inline="always")
        def _three(law, x, y, z):
            fn = choose(law)
            return lambda law, x, y, z: fn(law, x, y, z)
    elif arity == 4:
        @overload(stub, inline="always")
        def _four(law, x, y, z, w):
            fn = choose(law)
            return lambda law, x, y, z, w: fn(law, x, y, z, w)
    else:
        @overload(stub, inline="always")
        def _one(law, x):
            fn = choose(law)
            return lambda law, x: fn(law, x)


def _constant(stub, field):
    @overload(stub, inline="always")
    def _choose(law):
        value = bool(getattr(_BY_PARAMS[law.instance_class], field))

        def impl(law):
            return value
        return impl


@overload(linear_state, inline="always")
def _linear_state(law, v):
    fn = _BY_PARAMS[law.instance_class].linear_state
    if fn is None:
        # a law without the form: never reached at run time (methods.Method.refusal refuses the
        # method for a law with a state; a law without one takes no state stages)
        return lambda law, v: (math.nan, math.nan)
    return lambda law, v: fn(law, v)


@overload(creeps, inline="always")
def _creeps(law):
    value = _BY_PARAMS[law.instance_class].creeps
    return lambda law: value


def _optional(stub, field, arity, pair):
    """Compile calls of `stub` to the law's optional function `field`; a law without it never
    reaches the call (creeps(law) is False), which compiles to a NaN (a pair of NaNs if `pair`)."""
    def choose(law):
        return getattr(_BY_PARAMS[law.instance_class], field)

    if arity == 2:
        @overload(stub, inline="always")
        def _two(law, x, y):
            fn = choose(law)
            if fn is not None:
                return lambda law, x, y: fn(law, x, y)
            return (lambda law, x, y: (math.nan, math.nan)) if pair else (lambda law, x, y: math.nan)
    else:
        @overload(stub, inline="always")
        def _three(law, x, y, z):
            fn = choose(law)
            if fn is not None:
                return lambda law, x, y, z: fn(law, x, y, z)
            return (lambda law, x, y, z: (math.nan, math.nan)) if pair else (lambda law, x, y, z: math.nan)


_optional(creep_weakening, "creep_weakening", 2, pair=False)
_optional(friction_slopes, "friction_slopes", 2, pair=True)
_optional(creep_state, "creep_state", 3, pair=True)

for _stub in (friction, threshold, state_rate, rest_state, onset_delay, implicit_state, stiff_limit,
              rk4_unstable):
    _dispatch(_stub, _stub.__name__)
for _stub in (has_state, loader_moves):
    _constant(_stub, _stub.__name__)


@nb.njit(cache=True)
def rest_states(law, psi, dt):
    """psi of every block after dt[i] at rest (arrays; a new array)."""
    out = np.empty_like(psi)
    for i in range(psi.shape[0]):
        out[i] = rest_state(law, psi[i], dt[i])
    return out
