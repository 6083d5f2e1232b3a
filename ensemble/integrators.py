"""Event integrators as the config names them, and the kernels' parameter record built from the config.

The registry itself, `INTEGRATORS` (config name -> model.methods.Method: tableau, stages, control
exponent, description), lives beside the kernels in model/methods.py, since it decides what they
compile; adding a method is one entry there. All run through the same event kernel
(ensemble.model.event.integrate_event), which locates sticks and onsets inside a step the same way
for each.
"""
from .model import laws
from .model.methods import METHODS as INTEGRATORS
from .model.params import KernelParams

__all__ = ["INTEGRATORS", "kernel_params"]


def kernel_params(model, integrator):
    """The kernels' parameter record (model.params.KernelParams) from [model] and [integrator]
    (config dataclasses)."""
    max_steps = int(min(2 * integrator.max_duration / integrator.dt + 1e6, 2**62))
    return KernelParams(l2=model.l ** 2, nu=model.nu, law=laws.get(model.law).kernel_params(model),
                        method=INTEGRATORS[integrator.method].kernel_params(), dt=integrator.dt,
                        rtol=integrator.rtol, atol=integrator.atol, max_step=integrator.max_step,
                        max_duration=integrator.max_duration, max_steps=max_steps,
                        creep_tol=integrator.creep_tol)
