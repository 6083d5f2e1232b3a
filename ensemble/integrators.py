"""Registry of event integrators: config name -> (batch kernel, single-event kernel)."""
from dataclasses import dataclass

from .model.chain import simulate_rk4
from .model.rk4 import integrate_event as integrate_event_rk4


@dataclass(frozen=True)
class Integrator:
    simulate: object      # numba kernel: a batch of events (see model.chain.simulate_rk4)
    event: object         # numba kernel: one event from a given state (see model.rk4.integrate_event)
    description: str


INTEGRATORS = {
    "rk4": Integrator(simulate_rk4, integrate_event_rk4,
                      "classical fourth-order Runge-Kutta, fixed step dt, on the sliding blocks; "
                      "stick and onset located inside the step"),
}
