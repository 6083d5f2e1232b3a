"""The kernels' parameters as one record, passed as one argument from the runner to the innermost step.

numba takes a namedtuple as a nopython argument (a struct of its fields, read by name: `p.l2`), so no
kernel signature restates the order of the fields. The record is built by keyword only: exchanging two
fields (rtol and atol, say) is a visible change of names, never a silent change of position.
ensemble.integrators.kernel_params builds it from the config.
"""
from collections import namedtuple

_Fields = namedtuple("KernelParams", "l2 nu geom law method dt rtol atol max_step max_duration max_steps creep_tol")
_INTEGERS = ("max_steps",)
_RECORDS = ("geom", "law", "method")     # records of their own classes (below); the others are float64


class KernelParams(_Fields):
    """Model and integrator parameters of the event kernels (dimensionless, c-free frame).

    l2            l^2, the stiffness of the springs between blocks relative to the driver spring
    nu            loading velocity of the driver plate
    geom          the geometry's record, a namedtuple of that geometry's class (model/geometry/): the kernels are
                  compiled once per geometry, and each call of a geometry function resolves to it (the chain's
                  holds l2 too: the kernels not yet moved to the geometry read p.l2)
    law           the friction law's parameters, a namedtuple of that law's class (model/laws/): the
                  kernels are compiled once per law, and each call of a law function resolves to it
    method        the integrator's record (model/methods.py, MethodRecord: index, adaptive,
                  control_exponent), one type for every method: the kernels are compiled once per
                  law with every method's stepper, and take_step calls the one of p.method.index
    dt, rtol, atol, max_step, max_duration, creep_tol
                  the [integrator] keys of the same names, as declared (meaning, unit, the methods
                  that read them) in ensemble.integrators.KEYS; here max_step and max_duration may
                  be inf (no bound), and an event longer than max_duration (local time since its
                  onset) ends with TOO_LONG
    max_steps     steps of one event, rejected ones included, after which it ends with TOO_LONG (a
                  backstop behind max_duration for steps too small to reach it)
    """
    __slots__ = ()

    def __new__(cls, **fields):
        if set(fields) != set(cls._fields):
            missing = [f for f in cls._fields if f not in fields]
            unknown = [f for f in fields if f not in cls._fields]
            raise TypeError(f"KernelParams: missing {missing}, unknown {unknown}")
        # one type per field, so that every caller reaches the same compiled kernel
        return super().__new__(cls, *(int(fields[f]) if f in _INTEGERS else
                                      fields[f] if f in _RECORDS else float(fields[f]) for f in cls._fields))

    def __getnewargs_ex__(self):
        """For pickle and copy, which would otherwise call __new__ with the fields by position."""
        return (), self._asdict()
