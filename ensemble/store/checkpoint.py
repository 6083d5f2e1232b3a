"""A task's state between events as a checkpoint slot holds it, the commit row in use, and what a
writer knows of a task when a rank takes it up."""
from dataclasses import dataclass

import numpy as np

from ..model.workspace import NEPISODE, Workspace
from .schema import OPEN


def carries_creep(model):
    """A record of this model (config.Model) keeps a creep state in its checkpoint slots: some block of its
    chain can creep (model/creep.py `possible`; not for a law that never creeps, nor above the blocks'
    stiffness). Fixed at creation in /checkpoint/creep."""
    from ..config import Integrator
    from ..integrators import kernel_params
    from ..model.creep import possible
    return bool(possible(kernel_params(model, Integrator()), model.blocks))


def state_size(n, creep=False, episode_columns=NEPISODE):
    """Floats of one checkpoint slot of an n-block record (creep: with its creep state, of an episode table
    of `episode_columns`, EPISODE_COLUMNS)."""
    return 4 * n + 2 + (Workspace.creep_size(n, episode_columns) if creep else 0)


class Checkpoint:
    """A task's between-events state: forces, psi, their times (N x 2), compensated clock, events done,
    and for a chain that can creep its creep phase's state (Workspace.creep_state; None: it has none)."""

    def __init__(self, force, psi, since, clock, done, creep=None):
        self.force, self.psi, self.since, self.clock, self.done = force, psi, since, clock, done
        self.creep = creep

    def pack(self):
        return np.concatenate([self.force, self.psi, self.since.ravel(), self.clock,
                               *(() if self.creep is None else (self.creep,))])

    @classmethod
    def unpack(cls, flat, done, n):
        """The inverse of pack for an n-block chain (a creep state if flat is longer than 4 n + 2)."""
        base = state_size(n)
        return cls(flat[:n].copy(), flat[n:2 * n].copy(), flat[2 * n:4 * n].reshape(n, 2).copy(),
                   flat[4 * n:base].copy(), int(done), flat[base:].copy() if len(flat) > base else None)


@dataclass(frozen=True)
class Head:
    """The commit in use of one task: its slot and the fields of its row."""
    slot: int
    seq: int
    done: int
    written: int
    state_crc: int
    events_crc: int


@dataclass
class TaskRecord:
    """What a writer knows of a task when a rank takes it up."""
    checkpoint: Checkpoint = None   # None: start from the initial state
    written: int = 0                # events stored (the checkpoint covers them)
    status: int = OPEN
    integrator: str = ""            # its [integrator] as TOML text
    error: str = ""
    damaged: str = ""               # what is wrong with its record (tables.py): rerun it from its start
    histories: int = 0              # event histories of its committed rows kept (histories.py)

