"""Event integrators as the config names them: the [integrator] keys, and the kernels' parameter record.

The registry itself, `INTEGRATORS` (config name -> model.methods.Method: scheme, stages, control
exponent, description), lives beside the kernels in model/methods.py, since it decides what they
compile; adding a method is one entry there. All run through the same event kernel
(ensemble.model.event.integrate_event), which locates sticks and onsets inside a step the same way
for each.

`KEYS` below declares every [integrator] key once: its default, unit, valid range, meaning and the
methods that read it. The config's Integrator section and its checks (config.py, config_rules.py),
the kernels' parameter record (kernel_params, model/params.py) and the exported tables
(analysis/export_tables.py) all read it; a new key is one entry here (and a field of KernelParams
if the kernels read it).
"""
from dataclasses import dataclass

from .model import geometry, laws
from .model.methods import METHODS as INTEGRATORS
from .model.params import KernelParams

__all__ = ["INTEGRATORS", "KEYS", "Key", "kernel_params"]


@dataclass(frozen=True)
class Key:
    """An [integrator] key."""
    default: object       # its type is the key's type (float, or str for the method)
    unit: str             # as the catalog names units ("model time", "1", ...)
    meaning: str          # one line, for the config's docs and the exported tables
    check: object = None  # value -> bool (None: any value of the key's type)
    rule: str = ""        # what check requires, for the error message ("> 0")
    adaptive: bool = False  # read by the adaptive methods only (rk4, at its fixed step, ignores it)

    def methods(self):
        """Names of the methods (INTEGRATORS) that read the key."""
        return tuple(name for name, m in INTEGRATORS.items() if m.adaptive or not self.adaptive)

    @property
    def described(self):
        """The meaning, with the methods that read the key."""
        return f"adaptive methods: {self.meaning}" if self.adaptive else self.meaning


# integrator.rtol's default: the fastest ark4 tolerance whose magnitudes and recurrence times are
# indistinguishable from rtol 1e-7's at 1e5 events per point (b = 20 and 50, N = 800); 1e-3's
# recurrence times at b = 50 are not (benchmarks/statistics.py --catalogs, docs/benchmarks.md).
# The method's default is ark4 in the dataclass; a config file without it takes its law's
# (Law.method: exp4 for the aging law, ark4 for the others; config.from_dict).
CREEP_TOL_FLOOR = 1e-12
KEYS = {
    "method": Key("ark4", "text", "event integrator: "
                  + ", ".join(f"{name} ({m.kind})" for name, m in INTEGRATORS.items())
                  + "; a config without it takes its law's (exp4 for the aging law, ark4 for the others)"),
    "dt": Key(1e-3, "model time", "step of rk4; first step of the adaptive methods",
              lambda x: 0 < x <= 1, "in (0, 1]"),
    "rtol": Key(1e-4, "1", "relative tolerance of the local error per step", lambda x: 0 < x < 1, "in (0, 1)",
                adaptive=True),
    "atol": Key(1e-12, "model length", "absolute tolerance (slip, velocity)", lambda x: x > 0, "> 0",
                adaptive=True),
    "max_step": Key(0.5, "model time", "largest step", lambda x: x > 0, "> 0", adaptive=True),
    "max_duration": Key(1e5, "model time", "an event lasting longer is an error", lambda x: x > 0, "> 0"),
    # the creep phase: a law that creeps, b below a block's stiffness (model/creep.py)
    # its floor: a creep step's error estimate is a difference of psi-rates over steps of psi ~ 10-40, whose
    # rounding is ~1e-14; at 1e-14 (b = 15, N = 100) the steps shrink until the event exceeds max_duration,
    # at 1e-13 a run crawls (0.1 events/s, 1e-6: hundreds), so the floor keeps a factor 100 above the rounding
    "creep_tol": Key(1e-6, "1", "creep phase: local error of the state psi per creep step",
                     lambda x: CREEP_TOL_FLOOR <= x < 1,
                     f"in [{CREEP_TOL_FLOOR:g}, 1): below, a creep step's error is the rounding of psi"),
}


def kernel_params(model, integrator):
    """The kernels' parameter record (model.params.KernelParams) from [model] and [integrator]
    (config dataclasses): a key of KEYS the kernels read is the field of the same name (the method
    becomes its record)."""
    max_steps = int(min(2 * integrator.max_duration / integrator.dt + 1e6, 2**62))
    return KernelParams(l2=model.l ** 2, nu=model.nu, geom=geometry.get(model.geometry).kernel_params(model),
                        law=laws.get(model.law).kernel_params(model),
                        method=INTEGRATORS[integrator.method].kernel_params(), max_steps=max_steps,
                        **{name: getattr(integrator, name) for name in KEYS
                           if name != "method" and name in KernelParams._fields})
