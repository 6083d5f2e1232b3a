"""Registry of event integrators: config name -> kernel method and description.

All run through the same event kernel (ensemble.model.event.integrate_event),
which locates sticks and onsets inside a step the same way for each.
"""
from dataclasses import dataclass

from .model.event import ARK3, ARK4, ARK5, RK4
from .model import laws
from .model.params import KernelParams


@dataclass(frozen=True)
class Integrator:
    code: int             # method id understood by the kernels
    stages: int           # right-hand-side evaluations per block and step
    description: str


INTEGRATORS = {
    "rk4": Integrator(RK4, 4, "classical fourth-order Runge-Kutta with fixed step integrator.dt "
                           "(the paper's method); stable only while dt / theta < 2.785"),
    "ark3": Integrator(ARK3, 4, "adaptive IMEX Runge-Kutta ARK3(2)4L[2]SA: explicit in slip and "
                             "velocity, L-stable implicit in the state; step controlled by "
                             "integrator.rtol / atol, at most integrator.max_step"),
    "ark4": Integrator(ARK4, 6, "adaptive IMEX Runge-Kutta ARK4(3)6L[2]SA: fourth order, otherwise "
                             "as ark3 (explicit in slip and velocity, L-stable implicit in the "
                             "state, step controlled by integrator.rtol / atol, max_step)"),
    "ark5": Integrator(ARK5, 8, "adaptive IMEX Runge-Kutta ARK5(4)8L[2]SA: fifth order, otherwise "
                             "as ark3"),
}


def kernel_params(model, integrator):
    """The kernels' parameter record (model.params.KernelParams) from [model] and [integrator]
    (config dataclasses)."""
    max_steps = int(min(2 * integrator.max_duration / integrator.dt + 1e6, 2**62))
    return KernelParams(l2=model.l ** 2, nu=model.nu, law=laws.get(model.law).kernel_params(model),
                        method=INTEGRATORS[integrator.method].code, dt=integrator.dt, rtol=integrator.rtol,
                        atol=integrator.atol, max_step=integrator.max_step,
                        max_duration=integrator.max_duration, max_steps=max_steps)
