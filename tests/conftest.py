import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event
from ensemble.integrators import kernel_args
from ensemble.model.chain import simulate
from ensemble.model.workspace import NDIAG, UNLIMITED, Workspace

ROOT = Path(__file__).resolve().parents[1]


def developed_state(model, events, seed=1, dt=1e-3):
    """(force, psi) of a chain after `events` events from a random start."""
    rng = np.random.default_rng(seed)
    ws = Workspace(model.N)
    ws.load(-rng.random(model.N), np.zeros(model.N))
    clock = np.zeros(2)
    t = np.empty(events)
    epi = np.empty(events, dtype=np.int64)
    diag = np.empty((events, NDIAG))
    status, k = simulate(*ws.arrays, clock, *kernel_args(model, Integrator(method="rk4", dt=dt)), events, UNLIMITED, t, epi, diag)
    assert status == 0
    return ws.state(clock, model.nu)


def next_event(force, psi, model, dt, v_start=0.0):
    """Jump to the next onset and integrate that event with fixed-step RK4 at dt."""
    epicenter, _, f, p = advance_to_onset(force, psi, model)
    f[epicenter] = model.b * p[epicenter]
    return epicenter, check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=dt), v_start))


def run_cli(*args, cwd=None, timeout=600):
    """`python -m ensemble ARGS` in a subprocess; a hang fails the test (TimeoutExpired) instead of the suite."""
    env = dict(os.environ, NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))
    return subprocess.run([sys.executable, "-m", "ensemble", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=timeout)


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
            if isinstance(v, str):
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
