"""Event integrators: the registry (config name -> Method), and the calls through which the kernel steps.

An entry's tableau decides the rest: an IMEX pair of tableaux.py gives an adaptive method (its
stages, its step-size control exponent from the embedded order, its error weights), an
exponential scheme of exponential.py the adaptive exponential integrator written out there
(_STEPPERS: the stepper of each kind of tableau), None the classical RK4 at the fixed step dt. The kernels receive the method as a record
(KernelParams.method) of a class of its own, so numba compiles them once per method, and each
call here resolves at compile time to that method's stepper with its tableau frozen in as
constants: no branch on the method at run time (the friction laws' pattern, laws/__init__.py).

The registry lives beside the kernels because it decides what they compile: the numba cache is
keyed on the sources of this package (model/__init__.py).

Adding a method: its pair in tableaux.py, one entry in METHODS. A method may refuse a friction law
(Method.refusal: exp4 needs a state linear in theta = exp(psi)).
"""
import functools
from collections import namedtuple
from dataclasses import dataclass

import numba as nb
import numpy as np
from numba.extending import overload

from .exponential import ETDRK4_KROGSTAD, ExponentialScheme, exp_step
from .steppers import ark_step, rk4_step
from .tableaux import ARK324, ARK436, ARK548, ArkPair
from .workspace import ARK_STAGES


@dataclass(frozen=True)
class Method:
    """An event integrator as the config names it."""
    name: str             # the value of integrator.method
    tableau: object       # an adaptive method's pair: IMEX (tableaux.ArkPair) or exponential
                          # (exponential.ExponentialScheme); None: classical RK4
    description: str      # one paragraph, for the docs and `validate`

    def __post_init__(self):
        if self.tableau is not None and len(self.tableau.c) > ARK_STAGES:
            raise ValueError(f"{self.name}: {len(self.tableau.c)} stages, the work array holds "
                             f"{ARK_STAGES} (workspace.ARK_STAGES)")
        # the record's class, importable by name: pickle and numba's cache index find it so
        record = namedtuple(self.name.upper(), ["control_exponent"])
        record.__module__ = __name__
        record.method = self
        globals()[record.__name__] = record
        object.__setattr__(self, "_record", record)

    @property
    def adaptive(self):
        return self.tableau is not None

    @property
    def stages(self):
        """Right-hand-side evaluations per block and step."""
        return len(self.tableau.c) if self.adaptive else 4

    @property
    def control_exponent(self):
        """-1 / (q + 1), q the order of the embedded method (0 for RK4, which has none)."""
        return -1.0 / (self.tableau.embedded_order + 1) if self.adaptive else 0.0

    def kernel_params(self):
        """The method's record for the kernels (KernelParams.method)."""
        return self._record(control_exponent=self.control_exponent)

    def refusal(self, law):
        """Why this method cannot integrate the friction law `law` (laws.Law), one line naming the
        keys; None if it can."""
        if isinstance(self.tableau, ExponentialScheme) and law.has_state and law.linear_state is None:
            return (f"integrator.method = {self.name!r} needs a state equation linear in theta = exp(psi) "
                    f"(Law.linear_state), which model.law = {law.name!r} does not have: choose another "
                    f"integrator.method")
        return None


METHODS = {m.name: m for m in (
    Method("rk4", None, "classical fourth-order Runge-Kutta with fixed step integrator.dt "
                        "(the paper's method); stable only while dt / theta < 2.785"),
    Method("ark3", ARK324, "adaptive IMEX Runge-Kutta ARK3(2)4L[2]SA: explicit in slip and "
                           "velocity, L-stable implicit in the state; step controlled by "
                           "integrator.rtol / atol, at most integrator.max_step"),
    Method("ark4", ARK436, "adaptive IMEX Runge-Kutta ARK4(3)6L[2]SA: fourth order, otherwise "
                           "as ark3 (explicit in slip and velocity, L-stable implicit in the "
                           "state, step controlled by integrator.rtol / atol, max_step)"),
    Method("ark5", ARK548, "adaptive IMEX Runge-Kutta ARK5(4)8L[2]SA: fifth order, otherwise "
                           "as ark3"),
    Method("exp4", ETDRK4_KROGSTAD, "adaptive exponential Runge-Kutta (Krogstad's ETDRK4 with an "
                                    "embedded order 3): classical RK4 in slip and velocity, the state "
                                    "theta = exp(psi) advanced exactly in its linear part, every stage "
                                    "explicit; step controlled by integrator.rtol / atol, max_step; laws "
                                    "with a state need Law.linear_state (aging)"),
)}


def _method(record_type):
    """The Method of a method record's numba type."""
    return record_type.instance_class.method


def _method_of(params_type):
    """The Method of a KernelParams record's numba type."""
    return _method(params_type.types[params_type.fields.index("method")])


def _ark_stepper(pair):
    c, ae, ai, bw, bd, gamma = pair.kernel_arrays()

    def step(W, act, na, n, tau, h, p, yrest, first, at_first):
        work, slip_time, err = ark_step(W, act, na, n, tau, h, p, yrest, c, ae, ai, bw, bd, gamma)
        return work, slip_time, err, _NO_SUMS, _NO_SUMS
    return nb.njit(error_model="numpy")(step)


_NO_SUMS = (0.0, 0.0)   # a stepper that evaluates every stage passes on no sums (take_step)


@nb.njit(error_model="numpy")
def _rk4_stepper(W, act, na, n, tau, h, p, yrest, first, at_first):
    work, slip_time, err = rk4_step(W, act, na, n, tau, h, p, yrest)
    return work, slip_time, err, _NO_SUMS, _NO_SUMS


# the stepper of each kind of tableau, and its error weights (b - bhat) for steppers.block_error
_STEPPERS = {
    ArkPair: (_ark_stepper, lambda pair: pair.kernel_arrays()[4]),
    ExponentialScheme: (lambda scheme: exp_step, lambda scheme: np.array(scheme.error_weights)),
}


@functools.cache
def _stepper(method):
    """The numba function that takes one step of `method` (compiled once a process; not inlined:
    one copy however often the kernel steps, with steppers.py's error model)."""
    if not method.adaptive:
        return _rk4_stepper
    return _STEPPERS[type(method.tableau)][0](method.tableau)


# The kernels' calls; each stub is replaced by numba with the method's own code.

def take_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    """One step of the method p.method of the active blocks from (Y0, V0, P0) by h (steppers.py);
    `first` (steppers.FIRST_*) says where its first stage is, at_first = (friction power, total
    slip) there when it is not FIRST_NEW. Returns (friction work, time integral of the total slip,
    error norm relative to the tolerances, 0 for RK4; at_first, at_last): the power and slip sums
    at the step's first and last evaluation, which a method that reuses neither leaves (0, 0)."""


def error_weights(method):
    """b - bhat of an adaptive method's pair (float array; steppers.block_error)."""


def adaptive(method):
    """The method controls its step (a compile-time constant)."""


@overload(take_step, inline="always")
def _take_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    step = _stepper(_method_of(p))
    return lambda W, act, na, n, tau, h, p, yrest, first, at_first: step(W, act, na, n, tau, h, p, yrest,
                                                                         first, at_first)


@overload(error_weights, inline="always")
def _error_weights(method):
    m = _method(method)
    bd = _STEPPERS[type(m.tableau)][1](m.tableau) if m.adaptive else np.zeros(0)
    return lambda method: bd


@overload(adaptive, inline="always")
def _adaptive(method):
    value = _method(method).adaptive
    return lambda method: value
