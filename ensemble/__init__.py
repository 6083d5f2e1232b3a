"""MPI-parallel ensemble runner for the Burridge-Knopoff chain with rate- and state-dependent friction.

Its packages, each listing its own modules in its __init__.py:

    model/          the numba kernels (arrays in, arrays out), the friction laws (model/laws/) and the integrators
    run/            a run: config -> tasks -> kernel calls on every rank -> one catalog
    store/          the HDF5 event catalog: schema, layout, the writers (HDF5 under MPI in one place), the reader
    slurm/          `python -m ensemble slurm`: the job templates of jobs/ filled from a config, and submitted

and the modules the commands and packages share:

    api.py          the Python front door: load_config (a path, a TOML text or a dict), simulate (in this process)
    version.py      the package's version
    __main__.py     `python -m ensemble`
    cli.py          the command line: run, resume, validate, status, slurm
    config.py       TOML config -> validated frozen dataclasses (the one source of parameter truth)
    config_rules.py the checks of a config's values: types, ranges, the points the kernels' arithmetic cannot hold
    sections.py     the top-level tables of a run config, by name
    population.py   [population]: a run of many faults, each fault's parameters drawn from stated distributions
    sweep.py        the tasks a config asks for: sweep x seeds (or x faults), and the spin-ups of run.branch
    integrators.py  the [integrator] keys declared once, and the kernels' parameter record built from a config
    events.py       single events from a given state: the entry point for tests and benchmarks
    energy.py       the energy balance of a stretch of a run, over its inertial events and creep episodes
    checks.py       the checks every command makes of its numeric options and its output paths
    filekind.py     what a file is, in words: a wrong argument gets a one-line answer, not a traceback
    space.py        disk space and the file-size limit, checked before HDF5 touches a file
    environment.py  the software stack of a run: which MPI, which HDF5 (with MPI or not), which catalog writer
    kernel_cache.py where numba keeps the compiled kernels: one place for every entry point
    pipes.py        `python -m ensemble status X | head -1` ends quietly: stdout's reader going away is no error
"""
from .version import __version__

# the Python front door (api.py, docs/api.md): `ensemble.simulate(config, "out.h5")`, `ensemble.load_config()`;
# found when first asked for, so that `import ensemble` stays light
API = ("RunError", "load_config", "simulate")
__all__ = ["__version__", *API]


def __getattr__(name):
    if name in API:
        from . import api
        return getattr(api, name)
    raise AttributeError(f"module 'ensemble' has no attribute {name!r}")
