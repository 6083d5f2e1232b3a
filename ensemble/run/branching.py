"""Branching (run.branch): which spin-ups a run needs, and the state a branch starts from.

Each parameter point is spun up once (sweep.spinups: from its seed 0's initial state, run.transient
events); its tasks then start from that state, each perturbed by its own stream (tasks.perturb,
tasks.branch_rng). The runner (runner.py, worker.py) runs the spin-ups first, then the tasks.
"""
from dataclasses import dataclass

import numpy as np

from ..store.checkpoint import Checkpoint
from ..store.schema import FAILED, OPEN
from ..model.workspace import CR_EP, CR_KEEP
from ..sweep import Task, point_tasks, spinups
from .tasks import branch_rng, perturb


@dataclass(frozen=True)
class Spin:
    """A point's spin-up to run (or read) before its tasks branch (run.branch)."""
    point: int
    task: Task      # whose initial state it starts from (sweep.spinups)
    rerun: bool     # its point's tasks all failed: a spin-up not finished failed, rerun it with `rerun`


def spins_needed(cfg, tasks, stored=None, rerun=None):
    """The spin-ups a run needs: those of the points with a task still to start from its branch point.

    stored: the catalog's tasks (reader.read_tasks) when resuming, None for a new run.
    """
    needed = []
    for spin in spinups(cfg, tasks):
        mine = [t.index for t in point_tasks(cfg, tasks, spin.point)]
        if stored is None:
            needed.append(Spin(spin.point, spin, False))
            continue
        status, done = stored["status"][mine], stored["events_done"][mine]
        failed = status == FAILED
        if np.any((status == OPEN) & (done == 0)) or (rerun is not None and np.any(failed)):
            needed.append(Spin(spin.point, spin, bool(np.all(failed))))
    return needed


def creeping(spun):
    """Which blocks of a spun-up state (Checkpoint) creep: its creep state's episode column CR_EP."""
    n = len(spun.force)
    if spun.creep is None:
        return np.zeros(n, dtype=bool)
    return spun.creep[:n * CR_KEEP].reshape(n, CR_KEEP)[:, CR_EP] > 0


def branch_start(cfg, task, spun):
    """The state a branched task starts from: its point's spun-up state (Checkpoint, its creep state
    included) with the task's own perturbation, no events done.

    Only blocks at rest are lowered: a creeping block's force is its friction (force balance, the
    creep phase's invariant), and lowered it would creep on out of balance; the perturbation of
    the others decorrelates the seeds all the same. Every block still draws its number, so the
    stream does not depend on which blocks creep."""
    lowered = perturb(spun.force, cfg.run.perturbation, branch_rng(cfg, task))
    force = np.where(creeping(spun), spun.force, lowered)
    return Checkpoint(force, spun.psi.copy(), spun.since.copy(), spun.clock.copy(), 0,
                      None if spun.creep is None else spun.creep.copy())
