"""Single events from a given state: the entry point for tests and benchmarks."""
import time
from dataclasses import dataclass

import numpy as np

from .config import Integrator
from .energy import stiffness_product
from .integrators import kernel_params
from .model import laws
from .model.event import integrate_event
from .model.schedule import build_schedule, tree_min
from .model.workspace import (D_BLOCK_STEPS, D_CUTS, D_DURATION, D_ELASTIC, D_ENERGY_SCALE, D_LOAD_WORK, D_REJECTED,
                              D_RESIDUAL, D_SLIP, D_STEPS, D_STRESS_DROP, D_N_ONSET, D_T_SPREAD, D_T_WIDEST,
                              D_N_WIDEST, D_VMAX, D_WORK, NTRACE, OK, STATUS_TEXT, Workspace)


@dataclass
class EventResult:
    status: int
    slip: float             # sum of the slips
    duration: float
    steps: int
    block_steps: int        # sum over steps of the number of sliding blocks
    rejected: int           # steps rejected by the error control (counted in steps)
    cuts: int               # steps cut at a located stick or onset and redone
    vmax: float
    friction_work: float    # int sum(Phi v) dt, c-free frame
    energy_residual: float  # dE_elastic + friction work - loading work
    energy_scale: float     # sum of the magnitudes of the terms of that balance
    elastic_change: float   # dE_elastic: the slip's, at the load of the onset (workspace.D_ELASTIC)
    load_work: float        # work of the load's advance since the onset (workspace.D_LOAD_WORK)
    profile: np.ndarray     # slip of every block
    force: np.ndarray       # state after the event (c-free frame)
    psi: np.ndarray
    seconds: float          # wall time of the event kernel alone (no set-up: what a run pays)
    stress_drop: float      # mean force drop of the slipped blocks by the slip (workspace.D_STRESS_DROP)
    nucleation: tuple       # (n_onset, t_spread, t_widest, n_widest): workspace.D_N_ONSET ...

    @property
    def relative_energy_residual(self):
        return relative_energy_residual(self.energy_residual, self.energy_scale)


def relative_energy_residual(residual, scale):
    """|residual| / scale, the sum of the magnitudes of the energy balance's terms (D_ENERGY_SCALE).

    In the c-free frame friction b psi changes sign while a block slides, so the
    friction work of an event can nearly cancel and is no scale (one such event:
    work -19 against an energy turnover of ~1e5). Works elementwise on arrays of events.
    """
    return abs(residual) / scale


def physical_state(u, theta, t, model):
    """Displacements u_i, states theta_i at time t -> (force, psi) in the c-free frame.

    force_i = (nu t - u_i) + l^2 (u_{i+1} - 2 u_i + u_{i-1}) - c with free ends on the chain, nu t - (K u)_i - c
    with the springs of another geometry (energy.stiffness_product).
    """
    u = np.asarray(u, dtype=float)
    if model.geometry != "chain":
        return (model.nu * t - stiffness_product(u, model) - (model.c if model.c is not None else 0.0),
                np.log(np.asarray(theta, dtype=float)))
    lap = np.zeros_like(u)
    lap[:-1] += u[1:] - u[:-1]
    lap[1:] += u[:-1] - u[1:]
    force = (model.nu * t - u) + model.l ** 2 * lap - (model.c if model.c is not None else 0.0)
    return force, np.log(np.asarray(theta, dtype=float))


def advance_to_onset(force, psi, model):
    """Load quietly until the next onset: (epicenter, delay, force, psi) at the onset."""
    ws = Workspace(len(force))
    ws.load(force, psi)
    p = kernel_params(model, Integrator())
    build_schedule(ws.W, ws.since, ws.tree, p)
    _, epicenter = tree_min(ws.tree)
    delay = laws.get(model.law).onset_delay(p.law, force[epicenter], psi[epicenter], p.nu)
    return (epicenter, delay, *ws.state((delay, 0.0), p))


def run_event(force, psi, epicenter, model, integrator, v_start=0.0, trace=None):
    """Integrate one event from the given onset state; returns an EventResult.

    `trace`, an array (rows, NTRACE), receives a row per step tried (workspace.TRACE_COLUMNS).
    """
    n = len(force)
    ws = Workspace(n)
    ws.load(force, psi)
    profile = np.zeros(n)
    p = kernel_params(model, integrator)
    build_schedule(ws.W, ws.since, ws.tree, p)     # (simulate does this itself)
    clock = np.zeros(2)
    start = time.perf_counter()
    status = integrate_event(ws.arrays, clock, n, epicenter, v_start, p, profile,
                             np.zeros((0, NTRACE)) if trace is None else trace)
    seconds = time.perf_counter() - start
    # every block at the end (at the onset's time for a law whose loader stands still in events)
    end = ws.diag[D_DURATION] if laws.get(model.law).loader_moves else 0.0
    force, psi = ws.state((end, 0.0), p)
    d = ws.diag
    return EventResult(status, d[D_SLIP], d[D_DURATION], int(d[D_STEPS]), int(d[D_BLOCK_STEPS]),
                       int(d[D_REJECTED]), int(d[D_CUTS]), d[D_VMAX], d[D_WORK],
                       d[D_RESIDUAL], d[D_ENERGY_SCALE], d[D_ELASTIC], d[D_LOAD_WORK], profile, force,
                       psi, seconds, d[D_STRESS_DROP],
                       (int(d[D_N_ONSET]), d[D_T_SPREAD], d[D_T_WIDEST], int(d[D_N_WIDEST])))


def check(result, what="event"):
    """Raise if an EventResult failed."""
    if result.status != OK:
        raise RuntimeError(f"{what}: {STATUS_TEXT[result.status]}")
    return result
