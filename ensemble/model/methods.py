"""Event integrators: the registry (config name -> Method), and the calls through which the kernel steps.

An entry's tableau decides the rest: an IMEX pair of tableaux.py gives an adaptive method (its
stages, its step-size control exponent from the embedded order, its error weights), an
exponential scheme of exponential.py the adaptive exponential integrator written out there
(_STEPPERS: the stepper of each kind of tableau), None the classical RK4 at the fixed step dt.

The kernels receive the method as a record (KernelParams.method, a MethodRecord) of one type for every
method, so numba compiles them once per friction law and every method is in that one compilation:
take_step branches on the method's index once a step (not per block; docs/benchmarks.md measures its
cost) to the method's own stepper, each compiled with its tableau frozen in as constants. Each stepper
is the same code, with the same arithmetic, as when the kernels were compiled once per method.

The registry lives beside the kernels because it decides what they compile: the numba cache is
keyed on the sources of this package (model/__init__.py).

Adding a method: its pair in tableaux.py, one entry in METHODS. A method may refuse a friction law
(Method.refusal: exp4 needs a state linear in theta = exp(psi)).
"""
import functools
from dataclasses import dataclass
from typing import NamedTuple

import numba as nb
import numpy as np
from numba.extending import overload

from .exponential import ETDRK4_KROGSTAD, ExponentialScheme, exp_step
from .steppers import ark_step, rk4_step
from .tableaux import ARK324, ARK436, ARK548, ArkPair
from .workspace import ARK_STAGES


class MethodRecord(NamedTuple):
    """A method as the kernels see it (KernelParams.method): one type for every method, so that the
    kernels are compiled once per friction law, not once per law and method."""
    index: int                # its place in METHODS: take_step calls its stepper
    adaptive: bool            # it controls its step (rk4 does not)
    control_exponent: float   # -1 / (q + 1), q the embedded order (0 for rk4)


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
        return MethodRecord(index=list(METHODS).index(self.name), adaptive=self.adaptive,
                            control_exponent=self.control_exponent)

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


_STEP_ARGS = "W, act, na, n, tau, h, p, yrest, first, at_first"


@functools.cache
def _dispatch():
    """take_step's body: `if p.method.index == k: return stepper_k(...)` for every method k of the
    registry, in one function that numba inlines into the event loop, so that the step costs one
    comparison per method (once a step, not per block) and a direct call of the method's own stepper,
    as when the kernels were compiled once per method. Written out for the registry's methods."""
    steppers = {f"step_{k}": _stepper(m) for k, m in enumerate(METHODS.values())}
    lines = [f"def dispatch({_STEP_ARGS}):", "    index = p.method.index"]
    for k in range(len(steppers) - 1):
        lines += [f"    if index == {k}:", f"        return step_{k}({_STEP_ARGS})"]
    lines.append(f"    return step_{len(steppers) - 1}({_STEP_ARGS})")
    namespace = dict(steppers)
    exec("\n".join(lines), namespace)      # our own text: one branch per entry of the registry
    return namespace["dispatch"]


def _error_weight_rows():
    """(rows, lengths): row k of `rows` holds b - bhat of method k's pair (METHODS' order; none for rk4),
    its first lengths[k] entries; the rest are zero."""
    weights = [_STEPPERS[type(m.tableau)][1](m.tableau) if m.adaptive else np.zeros(0) for m in METHODS.values()]
    rows = np.zeros((len(weights), max(len(w) for w in weights)))
    for k, w in enumerate(weights):
        rows[k, :len(w)] = w
    return rows, np.array([len(w) for w in weights])


_ERROR_WEIGHTS, _STAGES = _error_weight_rows()


# The kernels' calls on the method record.

def take_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    """One step of the method p.method of the active blocks from (Y0, V0, P0) by h (steppers.py);
    `first` (steppers.FIRST_*) says where its first stage is, at_first = (friction power, total
    slip) there when it is not FIRST_NEW. Returns (friction work, time integral of the total slip,
    error norm relative to the tolerances, 0 for RK4; at_first, at_last): the power and slip sums
    at the step's first and last evaluation, which a method that reuses neither leaves (0, 0)."""


@overload(take_step, inline="always")
def _take_step(W, act, na, n, tau, h, p, yrest, first, at_first):
    return _dispatch()


@nb.njit(cache=True, inline="always")
def error_weights(method):
    """b - bhat of an adaptive method's pair (float array; steppers.block_error); empty for rk4."""
    return _ERROR_WEIGHTS[method.index, :_STAGES[method.index]]


@nb.njit(cache=True, inline="always")
def adaptive(method):
    """The method controls its step."""
    return method.adaptive
