import faulthandler
import os
import sys

import numpy as np
import pytest

from ensemble import catalog
from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.workspace import NDIAG, UNLIMITED, Workspace

from .processes import ROOT, child_env, run_bounded  # noqa: F401 (ROOT: test modules import it from here)

# -- a backstop behind the per-test timeout ----------------------------------------------------
# pytest-timeout (setup.cfg: `timeout`, method "signal") fails a test that runs too long and the
# session goes on; the test's `finally` blocks kill what it started. Its SIGALRM is served between
# bytecodes, though, and so is the thread method's timer thread (it needs the GIL): a numba kernel
# looping for ever in this process holds the GIL and is out of reach of both. faulthandler's
# watchdog is a C thread: BACKSTOP_SECONDS after the test's own limit it prints the stack of every
# thread and ends the session (exit 1).
BACKSTOP_SECONDS = 120
_STDERR = pytest.StashKey[int]()

# As in an activated .venv: the wheel stack's mpiexec (the mpich wheel) is the one beside python.
os.environ["PATH"] = os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", "")


def pytest_configure(config):
    # stderr itself, kept for the watchdog: during a test fd 2 is pytest's capture file
    config.stash[_STDERR] = os.dup(sys.stderr.fileno())
    # `make test` sets up the parallel stack and says so: then no test may skip for want of MPI-IO
    if os.environ.get("ENSEMBLE_TEST_STACK") == "parallel" and not catalog.has_parallel_hdf5():
        raise pytest.UsageError("ENSEMBLE_TEST_STACK=parallel, but this h5py has no MPI support "
                                "(rerun `make test`, or `make test STACK=wheels` to skip the MPI-IO tests)")


def pytest_collection_modifyitems(config, items):
    if catalog.has_parallel_hdf5():
        return
    skip = pytest.mark.skip(reason="h5py without MPI (the wheel stack): the parallel writer is not "
                                   "tested here; `make test` sets up the parallel stack and tests it")
    for item in items:
        if item.get_closest_marker("parallel_hdf5"):
            item.add_marker(skip)


def pytest_unconfigure(config):
    os.close(config.stash[_STDERR])


def timeout_of(item):
    """The timeout pytest-timeout applies to `item` (marker > --timeout > PYTEST_TIMEOUT > ini), 0 for none."""
    mark = item.get_closest_marker("timeout")
    if mark is not None:
        value = mark.args[0] if mark.args else mark.kwargs.get("timeout")
    else:
        value = item.config.getoption("timeout", None) or os.environ.get("PYTEST_TIMEOUT")
        if value is None:
            try:
                value = item.config.getini("timeout")
            except ValueError:      # pytest-timeout is not installed
                value = None
    return float(value or 0)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item, nextitem):
    limit = timeout_of(item)
    if limit > 0:
        faulthandler.dump_traceback_later(limit + BACKSTOP_SECONDS, exit=True, file=item.config.stash[_STDERR])
    try:
        return (yield)
    finally:
        if limit > 0:
            faulthandler.cancel_dump_traceback_later()


def developed_state(model, events, seed=1, dt=1e-3):
    """(force, psi) of a chain after `events` events from a random start."""
    rng = np.random.default_rng(seed)
    ws = Workspace(model.N)
    ws.load(-rng.random(model.N), np.zeros(model.N))
    clock = np.zeros(2)
    t = np.empty(events)
    epi = np.empty(events, dtype=np.int64)
    diag = np.empty((events, NDIAG))
    params = kernel_params(model, Integrator(method="rk4", dt=dt))
    status, k = simulate(ws.arrays, clock, params, events, UNLIMITED, t, epi, diag)
    assert status == 0
    return ws.state(clock, params)


def next_event(force, psi, model, dt, v_start=0.0):
    """Jump to the next onset and integrate that event with fixed-step RK4 at dt."""
    epicenter, _, f, p = advance_to_onset(force, psi, model)
    f[epicenter] = model.b * p[epicenter]
    return epicenter, check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=dt), v_start))


def run_cli(*args, cwd=None, timeout=600):
    """`python -m ensemble ARGS` in a subprocess; a hang fails the test, showing the output."""
    return run_bounded([sys.executable, "-m", "ensemble", *args], timeout, cwd=cwd, env=child_env())


def committed(out):
    """True once the run writing catalog `out` has committed a batch of events (readable, not yet renamed)."""
    try:
        _, tasks, _ = catalog.read_tasks(catalog.partial_path(out))
    except catalog.CatalogError:
        return False      # not created yet, or open for writing at that moment
    return tasks["events_written"].sum() > 0


def write_config(path, **sections):
    """A small config file: sections given as dicts override the test defaults."""
    base = {"model": {"N": 60, "b": 20.0}, "run": {"events": 40, "transient": 20, "seeds": 2},
            "integrator": {"method": "rk4", "dt": 1e-3}, "output": {"path": str(path.with_suffix(".h5"))}}
    for name, values in sections.items():
        base.setdefault(name, {}).update(values)
    lines = []
    for name, values in base.items():
        lines.append(f"[{name}]")
        for k, v in values.items():
            if isinstance(v, bool):
                lines.append(f"{k} = {'true' if v else 'false'}")
            elif isinstance(v, str):
                lines.append(f'{k} = "{v}"')
            elif isinstance(v, list):
                lines.append(f"{k} = {v!r}")
            else:
                lines.append(f"{k} = {v!r}")
        lines.append("")
    path.write_text("\n".join(lines))
    return path


@pytest.fixture(scope="module")
def events():
    """Pre-event states of the next few events of a developed chain, and RK4 references."""
    model = Model(N=100, b=20.0, a=2.0)
    force, psi = developed_state(model, 200)
    out = []
    for _ in range(4):
        epicenter, _, f, p = advance_to_onset(force, psi, model)
        f[epicenter] = model.b * p[epicenter]
        ref = check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=1.25e-4)))
        out.append((f, p, epicenter, ref))
        force, psi = ref.force, ref.psi
    return model, out
