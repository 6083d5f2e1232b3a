"""Numba kernels of the Burridge-Knopoff chain with rate- and state-dependent friction, one module per job:

    chain.py        a trajectory: quiet loading, the jump to the next onset, the event or creep episode (simulate)
    onset.py        quiet loading between events: when a block at rest starts to slide
    schedule.py     lazy quiet loading and the onset schedule between events
    event.py        one event on the active set, stepped by the chosen method
    transitions.py  where inside a step a block sticks or starts, located on the step's interpolant
    control.py      step-size control of the event loop: accepting a step, the size of the next
    steppers.py     the steps of the event integrators on the active set
    methods.py      the integrators' registry (config name -> Method) and the call through which the kernel steps
    tableaux.py     Butcher tableaux of the IMEX additive Runge-Kutta pairs, in exact fractions
    exponential.py  the exponential integrator exp4 (Krogstad's ETDRK4 in the state, RK4 in slip and velocity)
    creep.py        quasi-static creep, the third scene beside rest and inertial events
    undo.py         the undo log of the event in progress: the between-events state while an event is paused
    history.py      event histories: snapshots of an event's velocity and slip while it runs (output.history)
    geometry/       the geometries, one file each (today the chain), and the calls through which the kernels use one
    params.py       the kernels' parameters as one record, passed from the runner to the innermost step
    workspace.py    the work arrays shared by the kernels (their columns named), and the codes they return
    laws/           the friction laws, one file each, and the calls through which the kernels use a law

The kernels are compiled once per friction law, every method inside (methods.py); `python -m ensemble compile`
(ensemble/compiled.py) compiles every law ahead.

Kernels are pure: arrays, scalars and the parameter record (params.py) in, arrays out. Nothing here knows about
config objects, files, MPI or HDF5 (see ensemble.run.trajectory for the wrapper).

Numba's on-disk cache only notices changes to the file of the cached function
itself, not to the kernels it calls from other files; a stale cache would run
old physics silently. The cache therefore lives in a directory named after a
hash of all kernel sources, under the one cache root of every entry point:
<root>/bk-<hash> (ensemble/kernel_cache.py: $NUMBA_CACHE_DIR, else the
checkout's .numba_cache, else ~/.cache/bk-ensemble/numba).
"""
from pathlib import Path

import numba

from .. import kernel_cache

numba.config.CACHE_DIR = kernel_cache.directory(Path(__file__).parent)
