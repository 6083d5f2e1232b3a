"""Event integrators: the registry (config name -> Method), and the calls through which the kernel steps.

An entry is a name, a scheme and a description. The scheme decides the rest; it is any record with

    c                 its nodes (their number is the right-hand sides per block and step)
    embedded_order    the order q of its embedded method (None: a fixed step, not controlled)
    kind              a few words ("adaptive IMEX"; the config's description of integrator.method)
    stepper()         its numba step, with take_step's arguments and returns (below)
    error_weights()   b - bhat as floats, what steppers.block_error weighs the stages in W with
    refusal(law)      why it cannot integrate a friction law (laws.Law), or None

as an IMEX pair of tableaux.py (one stepper for every pair), the exponential scheme of
exponential.py and classical RK4 (steppers.ClassicalRK4) are.

The kernels receive the method as a record (KernelParams.method, a MethodRecord) of one type for every
method, so numba compiles them once per friction law and every method is in that one compilation:
take_step branches on the method's index once a step (not per block; docs/benchmarks.md measures its
cost) to the method's own stepper, each compiled with its tableau frozen in as constants. Each stepper
is the same code, with the same arithmetic, as when the kernels were compiled once per method.

The registry lives beside the kernels because it decides what they compile: the numba cache is
keyed on the sources of this package (model/__init__.py).

Adding a method: its scheme and stepper (a new pair is only its coefficients in tableaux.py), one
entry in METHODS (tests/test_new_integrator.py adds Heun's method in a copy of the package).
"""
import functools
from dataclasses import dataclass
from typing import NamedTuple

import numba as nb
import numpy as np
from numba.extending import overload

from .exponential import ETDRK4_KROGSTAD
from .steppers import ClassicalRK4
from .tableaux import ARK324, ARK436, ARK548
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
    scheme: object        # its scheme (the module's docstring): tableaux.ArkPair,
                          # exponential.ExponentialScheme, steppers.ClassicalRK4
    description: str      # one paragraph, for the docs and `validate`

    def __post_init__(self):
        if len(self.scheme.c) > ARK_STAGES:
            raise ValueError(f"{self.name}: {len(self.scheme.c)} stages, the work array holds "
                             f"{ARK_STAGES} (workspace.ARK_STAGES)")

    @property
    def adaptive(self):
        return self.scheme.embedded_order is not None

    @property
    def stages(self):
        """Right-hand-side evaluations per block and step."""
        return len(self.scheme.c)

    @property
    def control_exponent(self):
        """-1 / (q + 1), q the order of the embedded method (0 for RK4, which has none)."""
        return -1.0 / (self.scheme.embedded_order + 1) if self.adaptive else 0.0

    @property
    def kind(self):
        """The method in a few words."""
        return self.scheme.kind

    def kernel_params(self):
        """The method's record for the kernels (KernelParams.method)."""
        return MethodRecord(index=list(METHODS).index(self.name), adaptive=self.adaptive,
                            control_exponent=self.control_exponent)

    def refusal(self, law):
        """Why this method cannot integrate the friction law `law` (laws.Law), one line naming the
        keys; None if it can."""
        reason = self.scheme.refusal(law)
        return None if reason is None else (f"integrator.method = {self.name!r} {reason}: choose another "
                                            f"integrator.method")


METHODS = {m.name: m for m in (
    Method("rk4", ClassicalRK4(), "classical fourth-order Runge-Kutta with fixed step integrator.dt "
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


@functools.cache
def _stepper(method):
    """The numba function that takes one step of `method` (compiled once a process; not inlined:
    one copy however often the kernel steps, with steppers.py's error model)."""
    return method.scheme.stepper()


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
    """(rows, lengths): row k of `rows` holds b - bhat of method k's scheme (METHODS' order; none for rk4),
    its first lengths[k] entries; the rest are zero."""
    weights = [np.asarray(m.scheme.error_weights(), dtype=float) for m in METHODS.values()]
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
