"""One task's chain between events: the thin wrapper that turns a config into the kernel's arrays.

The kernels (ensemble.model) see arrays and numbers only; a Trajectory holds a task's workspace, its
clock and its event counter, builds the kernels' parameter record once (integrators.kernel_params) and
calls chain.simulate. event_rows turns the kernel's output into the catalog's columns; integrator_text
and parse_integrator are a task's [integrator] as the catalog stores it.
"""
import tomllib

import numpy as np

from ..config import ConfigError, parse_section, section_lines
from ..integrators import INTEGRATORS, kernel_params
from ..model.chain import simulate
from ..model.workspace import (D_ACROSS_FIRST, D_ACROSS_LAST,
                               CS_H, CS_NCREEP, CS_T_HI, CS_T_LO, D_DURATION, D_ENDING, D_FIRST, D_KIND, D_LAST, H_HI,
                               H_NA, H_LO, H_TAU, H_VALUES, HC_COUNT, HC_DROPPED, HC_DT, HC_ON, HC_RATIO, HC_READY,
                               HC_SLIP_MIN, D_NSLIP, D_SLIP, D_STRESS_DROP, D_N_ONSET, D_T_SPREAD, D_T_WIDEST,
                               D_N_WIDEST, EV_NA, EV_PHASE, EV_STEPS, EV_TAU, EV_VMAX, IN_EVENT, NDIAG, OK, PAUSED,
                               STATUS_TEXT, UNLIMITED, Workspace)
from ..store.checkpoint import Checkpoint, carries_creep
from ..store.errors import CatalogError
from .tasks import initial_state


class SimulationError(RuntimeError):
    """A task that cannot go on; the message names the task and the event."""


class Trajectory:
    """One task's chain between events: its workspace, clock and event counter."""

    def __init__(self, cfg, task, checkpoint=None, integrator=None, label=None, discarded=None, histories=None):
        """histories: the event histories the task has kept so far (output.history; None: it keeps none, as a
        spin-up)."""
        self.cfg = cfg
        self.task = task
        self.label = f"task {task.index}" if label is None else label     # in error messages
        self.discarded = cfg.run.discarded if discarded is None else discarded
        self.integrator = cfg.integrator if integrator is None else integrator
        out = cfg.output
        self.history_quota = out.history if histories is not None else 0
        self.histories_kept = histories or 0
        self.new_histories = []       # (slot, history) taken since the caller last collected them
        self.ws = Workspace(task.model.blocks, out.history_snapshots if self.history_quota else 0)
        hctl = self.ws.hctl
        hctl[HC_SLIP_MIN], hctl[HC_DT] = 10.0 ** out.history_mu, out.history_dt
        hctl[HC_RATIO] = 10.0 ** out.history_dlogv
        # a chain that can creep keeps its creep phase's state in its checkpoints (store/checkpoint.py)
        self.creeps = carries_creep(task.model)
        if checkpoint is None:
            self.ws.load(*initial_state(cfg, task))
            self.clock = np.zeros(2)
            self.done = 0      # rows completed (events and creep episodes), transient included
        else:
            self.ws.load(checkpoint.force, checkpoint.psi, checkpoint.since, creep=checkpoint.creep)
            self.clock = checkpoint.clock.copy()
            self.done = checkpoint.done
        self.params = kernel_params(task.model, self.integrator)

    def checkpoint(self):
        """The state after the last completed event (also while an event is paused; the creep state is
        that of the same moment, Workspace.creep_state)."""
        force, psi, since, clock = self.ws.between_events(self.clock)
        return Checkpoint(force, psi, since, clock, self.done, self.ws.creep_state() if self.creeps else None)

    def where(self):
        """Where the chain is now, in words: the event in progress (kernel calls pause inside one) or the creep
        phase, for a run that has gone long without a row (worker.py)."""
        ev, cs, n = self.ws.arrays.event, self.ws.arrays.cstate, self.task.model.blocks
        row = f"row {self.done}{' (transient)' if self.done < self.discarded else ''}"
        if ev[EV_PHASE] == IN_EVENT:
            return (f"{row}: an event in progress, {ev[EV_STEPS]:.3g} steps over a model time of {ev[EV_TAU]:.3g} "
                    f"since its onset, {int(ev[EV_NA])} of {n} blocks sliding, largest velocity {ev[EV_VMAX]:.3g}; "
                    f"it ends when every block is at rest, or fails at integrator.max_duration = "
                    f"{self.integrator.max_duration:g}")
        if cs[CS_NCREEP] > 0:
            return (f"{row}: {int(cs[CS_NCREEP])} of {n} blocks creeping at model time "
                    f"{cs[CS_T_HI] + cs[CS_T_LO]:.6g}, creep step {cs[CS_H]:.3g} (integrator.creep_tol = "
                    f"{self.integrator.creep_tol:g}); the episode ends when they stop or an event starts")
        return f"{row}: between events at model time {self.clock[0] + self.clock[1]:.6g}"

    def state(self):
        """(force, psi) of every block now (between events), c-free frame."""
        return self.ws.state(self.clock, self.params)

    def advance(self, n, budget=UNLIMITED):
        """Run n events; returns (onset times, epicenters, diagnostics rows).

        With a work `budget` (chain.simulate) fewer events may be returned: the call stops
        when the budget is spent, possibly in the middle of an event, which the next call continues.
        """
        t = np.empty(n)
        epicenter = np.empty(n, dtype=np.int64)
        diag = np.empty((n, NDIAG))
        ws = self.ws
        # snapshots while recording and short of the quota (switched between events only: history.py)
        ws.hctl[HC_ON] = float(self.done >= self.discarded and self.histories_kept < self.history_quota)
        status, k = simulate(ws.arrays, self.clock, self.params, n, budget, t, epicenter, diag)
        if status not in (OK, PAUSED):
            where = self.done + k
            phase = "transient " if where < self.discarded else ""
            creep = f", creep_tol={self.integrator.creep_tol}" if self.creeps else ""
            raise SimulationError(f"{self.label} {phase}event {where}: {STATUS_TEXT[status]} "
                                  f"(method={self.integrator.method}, dt={self.integrator.dt}, "
                                  f"rtol={self.integrator.rtol}{creep})")
        if ws.hctl[HC_READY]:
            ws.hctl[HC_READY] = 0.0
            self.new_histories.append((self.histories_kept, self._history(self.done + k - 1 - self.discarded)))
            self.histories_kept += 1
        self.done += k
        return t[:k], epicenter[:k], diag[:k]

    def _history(self, row):
        """The snapshots in the workspace as a history of recorded row `row` (ensemble/store/histories.py)."""
        hctl, n = self.ws.hctl, self.task.model.blocks
        H = self.ws.history[:int(hctl[HC_COUNT])]
        velocity, slip = np.zeros((len(H), n)), np.zeros((len(H), n))
        for r, snap in enumerate(H):
            lo, hi = int(snap[H_LO]), int(snap[H_HI]) + 1      # (valid there; the others at rest, no slip)
            velocity[r, lo:hi] = snap[H_VALUES + lo:H_VALUES + hi]
            slip[r, lo:hi] = snap[H_VALUES + n + lo:H_VALUES + n + hi]
        return {"row": row, "time": H[:, H_TAU].copy(), "sliding": H[:, H_NA].astype(np.int64), "velocity": velocity,
                "slip": slip,
                "dropped": int(hctl[HC_DROPPED])}


def _boundary(model, first, last, across_first, across_last):
    """The rupture reached an end of the chain, or on a lattice an edge along or across strike."""
    edge = (first == 0) | (last == model.N - 1)
    if model.M > 1:
        edge |= (across_first == 0) | (across_last == model.M - 1)
    return edge


def event_rows(task, t, epicenter, diag):
    """Kernel output -> catalog columns (EVENT_FIELDS, ensemble/store/schema.py)."""
    first = diag[:, D_FIRST].astype(np.int64)
    last = diag[:, D_LAST].astype(np.int64)
    across_first = diag[:, D_ACROSS_FIRST].astype(np.int64)
    across_last = diag[:, D_ACROSS_LAST].astype(np.int64)
    return {
        "task": np.full(len(t), task.index, dtype=np.int64), "t": t, "epicenter": epicenter,
        "mu": np.log10(diag[:, D_SLIP]), "slip": diag[:, D_SLIP], "first": first, "last": last,
        "n_slipped": diag[:, D_NSLIP].astype(np.int64),
        "boundary": _boundary(task.model, first, last, across_first, across_last),
        "duration": diag[:, D_DURATION],
        "kind": diag[:, D_KIND].astype(np.int8), "ending": diag[:, D_ENDING].astype(np.int8),
        "stress_drop": diag[:, D_STRESS_DROP], "n_onset": diag[:, D_N_ONSET].astype(np.int64),
        "t_spread": diag[:, D_T_SPREAD], "t_widest": diag[:, D_T_WIDEST],
        "n_widest": diag[:, D_N_WIDEST].astype(np.int64),
        "across_first": across_first, "across_last": across_last,
    }


def integrator_text(integrator):
    """A task's [integrator] as TOML text (stored per task in the catalog)."""
    return "\n".join(section_lines(integrator))


def parse_integrator(text, where):
    """The inverse of integrator_text, its keys checked as a config's."""
    try:
        section = parse_section("integrator", tomllib.loads(text))
        if section.method not in INTEGRATORS:
            raise ConfigError(f"integrator.method must be one of {', '.join(sorted(INTEGRATORS))}, "
                              f"got {section.method!r}")
        return section
    except (tomllib.TOMLDecodeError, ConfigError) as err:
        raise CatalogError(f"{where}: stored integrator cannot be read ({err})") from None
