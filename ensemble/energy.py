"""The energy balance of a stretch of a run, over its inertial events and creep episodes together.

An inertial event's row balances on its own (workspace.py: D_ELASTIC + D_WORK - D_LOAD_WORK = D_RESIDUAL).
A creep episode's does not: events and other episodes change its blocks' forces while it runs, and the
energy of the springs between them belongs to both, so its elastic change is not its own (D_ELASTIC and
D_RESIDUAL are NaN in its row). The balance closes over a stretch of the run instead, from the chain's
states at its two ends and every row's D_SLIP, D_WORK and D_LOAD_WORK (docs/numerics.md, "Energy of
creep"). In the c-free frame the forces are F = -K x with x = u + c - nu t and K the loader's springs and the
geometry's (on the chain I - l^2 Lap with free ends; every spring joins two blocks, so sum(K x) = sum(x)); the
elastic energy is E = x K x / 2 = F K^-1 F / 2 (the chain's by Thomas' algorithm, another geometry's by conjugate
gradients on K x from its springs: K is symmetric positive definite with eigenvalues between 1 and
max_i K_ii + sum_j K_ij, so they converge in a few hundred products) and the driver's power
nu sum(F). With S(t) the slip of every block since t0, sum F(t) = sum F(t0) + nu N (t - t0) - S(t), and each
row's D_LOAD_WORK = nu int (t - t_row) dS_row, so the driver's whole work from t0 to t1 is

    nu (t1 - t0) sum F(t0) + nu^2 N (t1 - t0)^2 / 2 - nu sum_rows D_SLIP (t1 - t_row) + sum_rows D_LOAD_WORK

and E(t1) - E(t0) + sum_rows D_WORK equals it, to the events' own residuals and the creep's rounding.
"""
from collections import namedtuple

import numpy as np

from .model import geometry as geometries
from .model.geometry.graph import stiffness_times
from .model.workspace import D_KIND, D_LOAD_WORK, D_SLIP, D_WORK, KIND_CREEP

Balance = namedtuple("Balance", [
    "load_work",        # the driver's whole work from t0 to t1
    "elastic_change",   # E(t1) - E(t0)
    "friction_work",    # every row's D_WORK (events and creep episodes), c-free frame
    "creep_work",       # ... of the creep episodes alone
    "residual",         # elastic_change + friction_work - load_work
])


def stiffness_product(x, model):
    """K x for the blocks of `model` (config.Model): its geometry's springs and the loader's."""
    x = np.ascontiguousarray(x, dtype=float)
    out = np.empty_like(x)
    stiffness_times(geometries.get(model.geometry).kernel_params(model), x, out)
    return out


def elastic_energy(force, model):
    """F K^-1 F / 2 for the forces F (c-free frame) of the blocks of `model` (config.Model)."""
    force = np.asarray(force, dtype=float)
    if model.geometry != "chain":
        return 0.5 * float(force @ _conjugate_gradients(force, model))
    n, l2 = len(force), model.l * model.l
    diag = 1.0 + l2 * ((np.arange(n) > 0).astype(float) + (np.arange(n) < n - 1))
    pivot, rhs = np.empty(n), np.empty(n)
    pivot[0], rhs[0] = diag[0], force[0]
    for i in range(1, n):
        m = -l2 / pivot[i - 1]
        pivot[i] = diag[i] + m * l2
        rhs[i] = force[i] - m * rhs[i - 1]
    x = np.empty(n)
    x[-1] = rhs[-1] / pivot[-1]
    for i in range(n - 2, -1, -1):
        x[i] = (rhs[i] + l2 * x[i + 1]) / pivot[i]
    return 0.5 * float(force @ x)


def _conjugate_gradients(force, model, rtol=1e-14, most=10000):
    """x with K x = force, to a residual of rtol |force|."""
    x, r = np.zeros_like(force), force.copy()
    d, rr = r.copy(), float(r @ r)
    goal = (rtol * np.sqrt(rr)) ** 2
    for _ in range(most):
        if rr <= goal:
            return x
        Kd = stiffness_product(d, model)
        step = rr / float(d @ Kd)
        x += step * d
        r -= step * Kd
        rr, rr_before = float(r @ r), rr
        d = r + (rr / rr_before) * d
    raise ArithmeticError(f"conjugate gradients on K did not converge in {most} products")


def balance(start, end, t, diag, model):
    """The energy balance (Balance) from `start` to `end`, two moments between events, each (force, time,
    in flight): the forces of every block then (Workspace.state) and Workspace.episodes_in_flight(); over the rows
    (onset times t, diagnostics diag) the kernels returned in between. An episode in flight counts with
    what it had done by `end`, less what it had done by `start` (its row, if any, carries both). `model`:
    config.Model of the run (its nu, springs and geometry)."""
    nu = model.nu
    (force0, t0, open0), (force1, t1, open1) = start, end
    creep = diag[:, D_KIND] == KIND_CREEP
    ts = np.concatenate([t, open1[0], open0[0]])
    slip, work, load = (np.concatenate([diag[:, d], open1[k], -open0[k]])
                        for k, d in ((1, D_SLIP), (2, D_WORK), (3, D_LOAD_WORK)))
    creep_work = float(np.sum(diag[creep, D_WORK]) + np.sum(open1[2]) - np.sum(open0[2]))
    span = t1 - t0
    load_work = (nu * (span * np.sum(force0) + 0.5 * nu * len(force0) * span * span - np.sum(slip * (t1 - ts)))
                 + np.sum(load))
    elastic = elastic_energy(force1, model) - elastic_energy(force0, model)
    friction = float(np.sum(work))
    return Balance(load_work, elastic, friction, creep_work, elastic + friction - load_work)
